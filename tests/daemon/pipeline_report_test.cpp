// The pipeline's figures: quantiles from the duration histogram, the limits printed beside them,
// the process's start they count from, and the Prometheus text they are published in (checked
// line by line against the exposition format's grammar).

#include "daemon/pipeline_report.hpp"

#include <map>
#include <random>
#include <regex>
#include <set>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "daemon/process_start.hpp"

namespace surroundd::daemon {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;
using std::chrono::nanoseconds;

TEST(DurationHistogram, QuantilesLieWithinOneBucketOfTheExactOnes) {
  DurationHistogram histogram;
  EXPECT_EQ(histogram.quantile(0.5), nanoseconds(0));
  std::mt19937 random(3);
  std::lognormal_distribution<double> durationMs(1.5, 0.8);
  std::vector<double> exact;
  for (int i = 0; i < 5000; ++i) {
    exact.push_back(durationMs(random));
    histogram.record(std::chrono::duration_cast<nanoseconds>(
        std::chrono::duration<double, std::milli>(exact.back())));
  }
  std::ranges::sort(exact);
  EXPECT_EQ(histogram.count(), 5000u);
  for (const double q : {0.5, 0.9, 0.99}) {
    const double want = exact[static_cast<std::size_t>(q * 5000) - 1];
    const double got = std::chrono::duration<double, std::milli>(histogram.quantile(q)).count();
    // The upper edge of the bucket the exact quantile falls in: above it by less than one bucket.
    EXPECT_GE(got, want) << q;
    EXPECT_LT(got, want * 1.06) << q;
  }
}

TEST(DurationHistogram, EdgesAndOutOfRangeDurations) {
  DurationHistogram histogram;
  histogram.record(nanoseconds(10));        // below 1 µs: the first bucket
  histogram.record(std::chrono::hours(1));  // above 100 s: the last
  EXPECT_EQ(histogram.quantile(0.5), DurationHistogram::upperEdge(0));
  EXPECT_EQ(histogram.quantile(1.0), DurationHistogram::upperEdge(DurationHistogram::kBuckets - 1));
  EXPECT_EQ(DurationHistogram::upperEdge(39), microseconds(10));
  EXPECT_EQ(DurationHistogram::upperEdge(159), milliseconds(10));
  DurationHistogram exact;
  exact.record(milliseconds(10));  // exactly on an edge: the bucket it closes
  EXPECT_EQ(exact.quantile(0.5), milliseconds(10));
}

PipelineReport sampleReport() {
  PipelineReport report;
  report.elapsed = std::chrono::seconds(11);
  report.setSpan = std::chrono::seconds(10);  // the frame rate counts from the first set
  report.frameSets = 300;
  report.staleDropped = 4;
  report.sync.unmatchedDropped[1] = 2;
  report.sync.lateMissing[2] = 5;
  report.cameras = {{"front", capture::CameraHealth::kOk, {300, 0, {}}, 1},
                    {"right", capture::CameraHealth::kFrozen, {298, 1, {}}, 0},
                    {"back", capture::CameraHealth::kOutOfSync, {295, 0, {}}, 2}};
  for (int i = 1; i <= 100; ++i) {
    report.stages[static_cast<std::size_t>(Stage::kStitch)].record(microseconds(100 * i));
    report.latency.record(milliseconds(30 + i % 7));
  }
  report.outputs = 2;
  report.outputDropped = 3;
  report.startup = milliseconds(620);
  report.startupFrom = StartupFrom::kProcess;
  return report;
}

TEST(PipelineReport, StatusNamesEveryCameraStageAndLatency) {
  const std::string text = statusText(sampleReport());
  EXPECT_THAT(text, ::testing::HasSubstr("30.0 fps"));
  EXPECT_THAT(text, ::testing::HasSubstr("front ok, right frozen, back out of sync"));
  EXPECT_THAT(text, ::testing::HasSubstr(
                        "stale sets skipped: 4; outputs: 2 (0 failed, 3 pictures dropped)"));
  EXPECT_THAT(text, ::testing::ContainsRegex(
                        "stage stitch +p50 +5\\.01 ms +p99 +10\\.00 ms +\\(100 sets, 10\\.0/s\\)"));
  EXPECT_THAT(text, ::testing::HasSubstr("latency capture to output: p50 33.5 ms"));
  EXPECT_THAT(text, ::testing::HasSubstr(
                        "frame rate: 30.0 fps (ISO 16505 / IEC 63033-3: >= 30 fps, met)\n"));
  EXPECT_THAT(text, ::testing::ContainsRegex(
                        "p99 3[0-9]\\.[0-9] ms \\(ISO 16505 / IEC 63033-3: p99 < 200 ms, met\\)"));
  EXPECT_THAT(text, ::testing::HasSubstr("first picture: 0.62 s after the process started "
                                         "(FMVSS 111: <= 2.0 s, met; target <= 1.0 s, met)\n"));
  EXPECT_THAT(text,
              ::testing::HasSubstr("camera back: out of sync, 295 frames, 0 faults, 2 queued"));
  EXPECT_THAT(text, ::testing::Not(::testing::HasSubstr("stage render")));  // nothing recorded
}

// Each limit is judged as its standard words it: at least 30 fps, latency below 200 ms (at the
// p99), the first picture within 2.0 s (and surroundd's 1 s target).
TEST(PipelineReport, FiguresAreJudgedAgainstTheirLimitsAtTheEdges) {
  EXPECT_THAT(frameRateWithLimit(30.0), ::testing::EndsWith(", met)"));
  EXPECT_THAT(frameRateWithLimit(29.96), ::testing::HasSubstr("30.0 fps (ISO 16505 / IEC 63033-3: "
                                                              ">= 30 fps, not met)"));
  const auto latencyOf = [](milliseconds duration) {
    DurationHistogram histogram;
    histogram.record(duration);
    return latencyWithLimit(histogram);
  };
  EXPECT_THAT(latencyOf(milliseconds(199)), ::testing::EndsWith("p99 < 200 ms, met)"));
  EXPECT_THAT(latencyOf(milliseconds(200)), ::testing::EndsWith("p99 < 200 ms, not met)"));
  EXPECT_EQ(startupWithLimits(milliseconds(1500), StartupFrom::kReload),
            "1.50 s after the reload started (FMVSS 111: <= 2.0 s, met; target <= 1.0 s, not met)");
  EXPECT_THAT(startupWithLimits(milliseconds(2000), StartupFrom::kPipeline),
              ::testing::HasSubstr("<= 2.0 s, met;"));
  EXPECT_THAT(startupWithLimits(milliseconds(2010), StartupFrom::kPipeline),
              ::testing::HasSubstr("<= 2.0 s, not met;"));

  PipelineReport starting = sampleReport();
  starting.startup.reset();
  EXPECT_THAT(statusText(starting), ::testing::HasSubstr("first picture: none yet\n"));
  EXPECT_THAT(prometheusText(starting), ::testing::Not(::testing::HasSubstr("startup_seconds{")));
}

// The drift watch: each seam's figure, and the verdict on the camera whose every seam is off.
TEST(PipelineReport, TheCalibrationWatchShowsEachSeamAndTheDriftingCamera) {
  PipelineReport report = sampleReport();
  EXPECT_THAT(prometheusText(report), ::testing::Not(::testing::HasSubstr("seam_misalignment")));
  report.cameras[0].calibrationDrifting = true;
  report.seams = {{"front/right", 13.4, 4.1, 0.71, true},
                  {"back/front", std::nullopt, 4.1, 0, false}};
  const std::string text = statusText(report);
  EXPECT_THAT(
      text, ::testing::HasSubstr("seam front/right: ground 13.4 cm apart at 4.1 m (response 0.71), "
                                 "misaligned\n"));
  EXPECT_THAT(text, ::testing::HasSubstr("seam back/front: not measured yet\n"));
  EXPECT_THAT(text, ::testing::HasSubstr("camera front: ok, calibration drifting, 300 frames"));
  EXPECT_THAT(text, ::testing::HasSubstr("camera right: frozen, 298 frames"));
  const std::string metrics = prometheusText(report);
  EXPECT_THAT(metrics,
              ::testing::HasSubstr("surroundd_seam_misalignment_cm{seam=\"front/right\"} 13.40\n"));
  EXPECT_THAT(metrics, ::testing::Not(::testing::HasSubstr("{seam=\"back/front\"}")));
  EXPECT_THAT(metrics,
              ::testing::HasSubstr("surroundd_camera_calibration_drifting{camera=\"front\"} 1\n"));
  EXPECT_THAT(metrics,
              ::testing::HasSubstr("surroundd_camera_calibration_drifting{camera=\"back\"} 0\n"));
}

// The colour correction says what it did at each seam, and where it left a seam or some of its
// blocks as they were because correcting them made them worse; with the balance, each camera's
// gains.
TEST(PipelineReport, TheColourCorrectionSaysWhereItLeftASeamAsItWas) {
  PipelineReport report = sampleReport();
  EXPECT_THAT(statusText(report), ::testing::Not(::testing::HasSubstr("colour")));
  report.colour =
      ColourReport{.balanced = true,
                   .seams = {{"front/right", 12.3, 2.1, 40, 2, 3, false},
                             {"back/right", 3.5, 3.5, 20, 0, 20, true}},
                   .balanceGains = {{1.02F, 0.98F, 1.0F}, {0.9F, 1.0F, 1.1F}, {1.0F, 1.0F, 1.0F}}};
  const std::string text = statusText(report);
  EXPECT_THAT(text, ::testing::HasSubstr("colour: poisson after the balance; front x1.02 0.98 1.00 "
                                         "(B G R), right x0.90 1.00 1.10 (B G R), back x1.00 1.00 "
                                         "1.00 (B G R)\n"));
  EXPECT_THAT(text, ::testing::HasSubstr(
                        "colour seam front/right: step 12.3 -> 2.1 levels, 2 of 40 blocks clamped; "
                        "3 blocks left as they were (correcting them made them worse)\n"));
  EXPECT_THAT(text, ::testing::HasSubstr("colour seam back/right: step 3.5 -> 3.5 levels, 0 of 20 "
                                         "blocks clamped; left as it was (correcting it made it "
                                         "worse)\n"));
}

// A suggested mount correction, and a camera turned past what a correction may make: the status
// and the metrics tell them apart.
TEST(PipelineReport, AMountTurnedPastTheBoundIsAFaultNotASuggestion) {
  PipelineReport report = sampleReport();
  report.mountWatch = MountWatchReport{.setsCompared = 40, .comparisons = 900, .cpuSeconds = 2.5};
  report.cameras[1].mountSuggestion = MountSuggestion{{1.5, -0.4, 0.2}, 0.3, 0.05, false};
  report.cameras[2].mountSuggestion = MountSuggestion{{8.0, 0.1, 0.0}, 0.0, 0.04, true};
  const std::string text = statusText(report);
  EXPECT_THAT(text, ::testing::HasSubstr(
                        "camera right: frozen, mount would turn yaw +1.5°, pitch -0.4°, roll +0.2° "
                        "(±0.05°), 298 frames"));
  EXPECT_THAT(text, ::testing::HasSubstr("mount has turned yaw +8.0°, pitch +0.1°, roll +0.0° "
                                         "(±0.04°): past the 5° a correction may make, check its "
                                         "mount"));
  const std::string metrics = prometheusText(report);
  EXPECT_THAT(metrics, ::testing::HasSubstr(
                           "surroundd_camera_mount_correction_deg{camera=\"right\",axis=\"yaw\"} "
                           "1.500\n"));
  EXPECT_THAT(metrics, ::testing::Not(
                           ::testing::HasSubstr("surroundd_camera_mount_correction_deg{camera=\"" +
                                                report.cameras[2].name + "\"")));
  EXPECT_THAT(metrics, ::testing::HasSubstr("surroundd_camera_mount_fault{camera=\"" +
                                            report.cameras[2].name + "\"} 1\n"));
  EXPECT_THAT(metrics, ::testing::HasSubstr("surroundd_camera_mount_fault{camera=\"right\"} 0\n"));

  // The calibration watch alone: its seams and refinement, and each camera's verdict.
  EXPECT_THAT(calibrationText(report), ::testing::HasSubstr("off"));
  report.seams = {{"front/right", 13.4, 4.1, 0.71, true, 1.2}};
  report.cameras[1].calibrationDrifting = true;
  EXPECT_EQ(calibrationText(report),
            "seam front/right: ground 13.4 cm apart at 4.1 m (response 0.71), misaligned; 1.2 cm "
            "with the mounts suggested\n"
            "mount refinement: 40 sets compared, 900 comparisons in the last solution, 2.5 s of "
            "CPU\n"
            "camera front: no drift seen\n"
            "camera right: calibration drifting, mount would turn yaw +1.5°, pitch -0.4°, roll "
            "+0.2° (±0.05°)\n"
            "camera back: no drift seen, mount has turned yaw +8.0°, pitch +0.1°, roll +0.0° "
            "(±0.04°): past the 5° a correction may make, check its mount\n");
  // correct: apply says what it made and took back.
  report.mountWatch->applying = true;
  report.mountWatch->applied = 2;
  report.mountWatch->reverted = 1;
  report.mountWatch->checking = true;
  EXPECT_THAT(calibrationText(report),
              ::testing::HasSubstr("2.5 s of CPU; corrections applied 2, taken back 1 (the last "
                                   "being checked)\n"));
  EXPECT_THAT(prometheusText(report),
              ::testing::HasSubstr("surroundd_mount_corrections_total{outcome=\"applied\"} 2\n"
                                   "surroundd_mount_corrections_total{outcome=\"taken_back\"} "
                                   "1\n"));
}

// A switch of view: its first picture, then the new view settled, held to the first picture's
// 2.0 s and surroundd's 0.5 s target; absent before any switch.
TEST(PipelineReport, AViewSwitchIsTimedToItsFirstPictureAndToTheNewViewSettled) {
  PipelineReport report = sampleReport();
  EXPECT_THAT(statusText(report), ::testing::Not(::testing::HasSubstr("view switch")));
  EXPECT_THAT(prometheusText(report), ::testing::Not(::testing::HasSubstr("view_switch_seconds{")));

  report.viewSwitch = ViewSwitchTime{milliseconds(40), std::nullopt};
  EXPECT_THAT(
      statusText(report),
      ::testing::HasSubstr("view switch: under way, first picture 0.04 s after the request\n"));
  EXPECT_THAT(prometheusText(report),
              ::testing::HasSubstr("surroundd_view_switch_seconds{picture=\"first\"} 0.040000\n"));
  EXPECT_THAT(
      prometheusText(report),
      ::testing::Not(::testing::HasSubstr("surroundd_view_switch_seconds{picture=\"settled\"}")));

  report.viewSwitch->settled = milliseconds(500);
  EXPECT_THAT(statusText(report),
              ::testing::HasSubstr("view switch: first picture 0.04 s, settled 0.50 s after the "
                                   "request (FMVSS 111: <= 2.0 s, met; target <= 0.5 s, met)\n"));
  EXPECT_THAT(
      prometheusText(report),
      ::testing::HasSubstr("surroundd_view_switch_seconds{picture=\"settled\"} 0.500000\n"));
  EXPECT_THAT(viewSwitchWithLimits({milliseconds(40), milliseconds(510)}),
              ::testing::EndsWith("target <= 0.5 s, not met)"));
  EXPECT_THAT(viewSwitchWithLimits({milliseconds(40), milliseconds(2010)}),
              ::testing::HasSubstr("<= 2.0 s, not met;"));
}

// The kernel's start time, not main's: it lies before this program's static initializers ran, and
// not long before (the loader maps the libraries in well under a minute).
const auto kStaticInitialization = std::chrono::steady_clock::now();

TEST(ProcessStartTime, LiesJustBeforeTheProgramsStaticInitialization) {
  const auto started = processStartTime();
  EXPECT_LE(started, kStaticInitialization);
  EXPECT_LT(kStaticInitialization - started, std::chrono::minutes(1));
}

TEST(PipelineReport, PrometheusTextFollowsTheExpositionFormat) {
  const std::string text = prometheusText(sampleReport());
  const std::regex help("# HELP (surroundd_[a-z_]+) .+");
  const std::regex type("# TYPE (surroundd_[a-z_]+) (counter|gauge|summary)");
  const std::regex sample(
      R"((surroundd_[a-z_]+)(\{[a-z]+="[^"]*"(,[a-z]+="[^"]*")*\})? (-?[0-9]+(\.[0-9]+)?))");
  std::istringstream lines(text);
  std::string line;
  std::string family;  // the family whose samples may follow
  std::set<std::string> seen;
  std::map<std::string, double> values;
  while (std::getline(lines, line)) {
    std::smatch match;
    if (std::regex_match(line, match, help)) {
      EXPECT_TRUE(seen.insert(match[1]).second) << "family declared twice: " << line;
      family = match[1];
      continue;
    }
    if (std::regex_match(line, match, type)) {
      EXPECT_EQ(match[1], family) << line;
      continue;
    }
    ASSERT_TRUE(std::regex_match(line, match, sample)) << "not a sample line: '" << line << "'";
    const std::string name = match[1];
    // Samples of a family are together, right after its HELP and TYPE.
    EXPECT_TRUE(name == family || name == family + "_sum" || name == family + "_count") << line;
    values[line.substr(0, line.rfind(' '))] = std::stod(match[4]);
  }
  EXPECT_EQ(values["surroundd_frame_sets_total"], 300);
  EXPECT_EQ(values["surroundd_stale_sets_dropped_total"], 4);
  EXPECT_EQ(values["surroundd_output_pictures_dropped_total"], 3);
  EXPECT_NEAR(values["surroundd_stage_seconds{stage=\"stitch\",quantile=\"0.5\"}"], 0.00501, 1e-5);
  EXPECT_EQ(values["surroundd_stage_seconds_count{stage=\"stitch\"}"], 100);
  EXPECT_EQ(values["surroundd_stage_seconds_count{stage=\"render\"}"], 0);
  EXPECT_EQ(values["surroundd_latency_seconds_count"], 100);
  EXPECT_EQ(values["surroundd_camera_healthy{camera=\"right\"}"], 0);
  EXPECT_EQ(values["surroundd_camera_health{camera=\"right\",state=\"frozen\"}"], 1);
  EXPECT_EQ(values["surroundd_camera_sync_dropped_total{camera=\"right\"}"], 2);
  EXPECT_EQ(values["surroundd_camera_sets_without_total{camera=\"back\"}"], 5);
  EXPECT_EQ(values["surroundd_camera_queue_depth{camera=\"back\"}"], 2);
  EXPECT_NEAR(values["surroundd_startup_seconds{since=\"process\"}"], 0.62, 1e-9);
  EXPECT_THAT(text, ::testing::HasSubstr("(FMVSS 111: at most 2; target 1)"));
  EXPECT_THAT(text, ::testing::HasSubstr("(ISO 16505 / IEC 63033-3: at least 30)"));
}

}  // namespace
}  // namespace surroundd::daemon
