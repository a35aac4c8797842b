#pragma once
// Poisson local colour correction (DESIGN.md §2.3, the paper's §2.3): per frame, each source
// camera's region of the panorama gets a smooth correction field that takes its colours to the
// target cameras' across every seam, solved at a reduced scale and applied to the stitched
// panorama after bicubic upsampling. Target cameras are left as they are.
//
// The field is multiplicative by default: it is solved for log(target / source), so the source
// keeps its own contrast and each pixel is scaled. Cameras differ by gain, white balance and
// vignetting, all of them factors, so an additive field (the paper's, `kAdditive`) matches the
// seam's mean but leaves bright and dark pixels next to it off by the gain difference times their
// distance from that mean.
//
// On real rigs the seam data is made robust (seam_statistics.hpp: trimmed means of usable samples,
// filtered along each seam, from the ground and never from the vehicle's body; the far ground,
// past the bowl's floor, as one band with its own median: correction_domain.hpp), the field is
// bounded to gains in [minGain, maxGain], and one rule stands above the rest: correction never
// makes a seam worse than none. After each solve, every seam's step (its typical block's: the
// target's levels against the source's as the field next to the seam leaves them) is compared
// with its step uncorrected, and so is each stretch of 16 blocks along it (near and far ground
// differ); a seam or stretch that got worse (by more than noise: 5 % and half a level) has its
// data dropped (gain 1 there) and its region is solved again. With the balance first
// (`balance`), "none" is still the cameras as they are: a dropped block's field gives its source
// the target's balance gain, so the step stays what it was. Clamps, seams with too little
// usable data and dropped seams are said once each in notesOfLastUpdate().
//
// Set up once (domain, systems, solver factorizations, buffers); update() and apply() are the
// per-frame calls and allocate nothing. A camera missing from a frame set leaves the seams it
// shares at their last values; missing for kLostAfterSets sets in a row it counts as lost and the
// domain changes: a lost source's region is left uncorrected, a lost target's seams become free
// (Neumann) borders. The domain and solvers for each set of cameras are built the first time it
// occurs (a one-off cost, said in notesOfLastUpdate()) and kept for when it occurs again.

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "common/pixel_format.hpp"
#include "processing/colour/colour_balance.hpp"
#include "processing/colour/correction_domain.hpp"
#include "processing/colour/poisson_solver.hpp"
#include "processing/colour/seam_statistics.hpp"
#include "processing/colour_field.hpp"
#include "processing/stitch/kernel_path.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::processing {

enum class CorrectionField { kMultiplicative, kAdditive };

// "multiplicative", "additive": the config's words.
std::string_view correctionFieldName(CorrectionField field);

struct ColourCorrectionSettings {
  double scale = 0.25;  // the field's resolution against the panorama's (1 / block size)
  CorrectionField field = CorrectionField::kMultiplicative;
  PoissonSolverKind solver = PoissonSolverKind::kAuto;
  double tolerance = 5e-5;         // iterative solver: relative residual
  double temporalSmoothing = 0.0;  // weight of the previous frame's seam data, 0..0.99
  double minGain = 0.5;            // the field's bounds, as gains (additive: the levels these
  double maxGain = 2.0;            //   gains would add to the seam's source level)
  bool groundSeams = true;         // seam data from the bowl's floor only
  // A global balance first (colour_balance.hpp): every camera's gains, fitted over the seams'
  // ground, take the cameras to their average, and the field corrects what is left.
  bool balance = false;
  double balanceSmoothing = 0.8;  // the previous set's share of the balance's gains, 0..0.99
  // The camera the balance takes the others to, by name; empty: the cameras' average.
  std::string balanceReference;

  bool operator==(const ColourCorrectionSettings&) const = default;
};

class PoissonColourCorrection {
 public:
  // Borrows the LUT and the pool; both must outlive this object. Throws std::invalid_argument for
  // a scale that does not fit the panorama.
  PoissonColourCorrection(const Rig& rig, const PanoramaSettings& panorama, const PanoramaLut& lut,
                          const ColourCorrectionSettings& settings, WorkPool& pool);
  ~PoissonColourCorrection();
  PoissonColourCorrection(const PoissonColourCorrection&) = delete;
  PoissonColourCorrection& operator=(const PoissonColourCorrection&) = delete;

  static constexpr int kLostAfterSets = 5;

  // How each seam of the last update() fared.
  struct SeamReport {
    std::uint8_t source = 0, target = 0;
    int blocks = 0, validBlocks = 0, clampedBlocks = 0;
    int droppedBlocks = 0;  // in stretches the correction would have made worse: left as they were
    bool dropped = false;   // the whole seam would have got worse: gain 1 all along it
    // Median over measured blocks of the mean over channels of |target - source| in levels:
    // without correction, and with the field as it leaves the source next to the seam.
    double stepUncorrected = 0, stepCorrected = 0;
  };

  // Things left out at set-up (regions without a seam to a target), to be logged once.
  const std::vector<std::string>& notes() const;
  // What the last update() changed in the domain, the first time cameras were lost or came back
  // in this combination (empty otherwise), to be logged.
  const std::vector<std::string>& notesOfLastUpdate() const { return changes_; }
  // The domain in use: the full rig's, or the one without the cameras lost now.
  const CorrectionDomain& domain() const;
  const ColourCorrectionSettings& settings() const { return settings_; }
  std::string solverNames() const;

  // Solves this frame's fields from the camera frames, held in `format` (common/pixel_format.hpp;
  // an empty Mat: that camera is missing). Returns the solvers' iterations, summed over regions
  // (0 for direct solvers).
  int update(std::span<const cv::Mat> frames, PixelFormat format = PixelFormat::kBgr);

  // Adds the fields to a panorama stitched from the same frames (8-bit BGR of the LUT's size).
  // `path`: the kernels to use (kernel_path.hpp), every one giving the same bytes.
  void apply(cv::Mat& panorama, KernelPath path = kNativeKernels);

  // A picture that shows the panorama elsewhere (a fixed view through its view LUT,
  // processing/stitch/view_lut.hpp): for each of its pixels, the 2x2 blocks of the field around
  // where it samples the panorama, and the source cameras' share of the panorama pixel nearest
  // to it (0: nothing to correct).
  struct ViewTap {
    std::uint32_t block = 0;  // top-left of the 2x2: row * grid width + column
    std::int16_t right = 1;   // from a block to the one on its right (columns wrap around)
    std::int16_t down = 0;    // to the one below (0 on the grid's last row)
    float fx = 0, fy = 0;
    std::uint16_t share = 0;  // 0..256
  };
  struct ViewSamples {
    cv::Size size;
    std::vector<ViewTap> taps;  // row-major
  };
  // Built once per view from where its pixels sample the panorama, in panorama pixels (NaN where
  // they do not), as composeViewLut() takes them.
  ViewSamples viewSamples(const cv::Mat& panoramaPositions) const;
  // Adds the fields to a picture of samples.size made from the same frames as the last update().
  // The fields are sampled bilinearly from the block grid, where apply() upsamples them
  // bicubically: they are smooth, so the two differ by a fraction of a level, at a quarter of the
  // taps. `path`: as apply()'s.
  void applyAt(const ViewSamples& samples, cv::Mat& picture, KernelPath path = kNativeKernels);
  // The same, each pair of rows then converted into `i420` (processing/stitch/i420_picture.hpp;
  // reallocated only if not of the picture's size) while it is still in the cache: the picture of
  // a view made for an encoder in one pass.
  void applyAt(const ViewSamples& samples, cv::Mat& picture, cv::Mat& i420,
               KernelPath path = kNativeKernels);

  const std::vector<SeamReport>& seams() const { return seamReports_; }
  // With settings().balance, each camera's B G R gains that apply() and the view's pictures take
  // before the field (processing/colour/camera_gains.hpp); empty without.
  std::span<const cv::Vec3f> cameraGains() const {
    return balance_ ? std::span<const cv::Vec3f>(balance_->gains()) : std::span<const cv::Vec3f>();
  }

  // The field at block resolution, CV_32FC3: the levels it adds to a pixel at 255, the most it
  // changes any pixel (0 outside the regions' reach). Additive: simply the levels it adds.
  const cv::Mat& field() const { return field_; }
  // The field as a stitcher applies it (processing/colour_field.hpp), borrowing this correction's.
  ColourField asColourField() const;

 private:
  struct RegionState;
  struct Configuration;
  Configuration& configurationFor(std::uint32_t presentCameras);
  void followLostCameras(std::span<const cv::Mat> frames);
  void gatherSeams(std::span<const cv::Mat> frames, PixelFormat format);
  // Fits the balance to this set's seam levels, then takes the levels and the seam data to what
  // they are after it.
  void balanceSeams(std::span<const cv::Mat> frames);
  // Measures part `part` of the seam blocks, with its own meter: of the regions' blocks counted
  // in turn, every meters_.size()-th from the part's, so that the parts cost alike.
  void measureSeamBlocks(std::size_t part, std::span<const cv::Mat> frames, PixelFormat format);
  // Gives the seam's blocks past the bowl's floor one value, their median (of each channel).
  void farGroundAsOneBand(const CorrectionRegion& region, const CorrectionSeam& seam,
                          RegionState& state);
  void solveRegions(std::span<const std::uint8_t> which);
  // Drops the data of seams the solved field makes worse than none; true when any was dropped.
  bool dropWorseningSeams();
  // The seam data that leaves a dropped seam block's step as it was uncorrected.
  float asItWas(const CorrectionRegion& region, const RegionState& state, std::size_t block,
                int channel) const;
  void noteOnce(std::vector<std::uint8_t>& said, std::size_t seam, std::string note);
  // `instance.template operator()<kField, kPath>()` for this correction's field and `path`
  // (a row kernel's instance); throws std::invalid_argument for a path this build lacks.
  template <typename Instance>
  auto kernelFor(KernelPath path, Instance instance) const;
  template <CorrectionField kField, KernelPath kPath>
  void applyRows(int first, int last, cv::Mat& panorama, std::vector<float>& columnBuffer) const;
  template <CorrectionField kField, KernelPath kPath>
  void applyAtRows(int first, int last, const ViewSamples& samples, cv::Mat& picture) const;
  // applyAt()'s kernel for this field and `path`, once the picture is checked against `samples`.
  using ViewRows = void (PoissonColourCorrection::*)(int, int, const ViewSamples&, cv::Mat&) const;
  ViewRows viewRowsFor(const ViewSamples& samples, const cv::Mat& picture, KernelPath path) const;

  const PanoramaLut& lut_;
  WorkPool& pool_;
  ColourCorrectionSettings settings_;
  Rig rig_;
  PanoramaSettings panorama_;
  // Per set of cameras not lost (bit c: camera c), its domain and solvers' state.
  std::map<std::uint32_t, std::unique_ptr<Configuration>> configurations_;
  Configuration* full_ = nullptr;    // every camera
  Configuration* active_ = nullptr;  // the cameras not lost now
  std::uint32_t activeCameras_ = 0;
  std::vector<int> missingSets_;  // per camera: frame sets in a row without it
  std::vector<std::string> changes_;
  std::vector<SeamReport> seamReports_;
  std::unique_ptr<ColourBalance> balance_;   // settings_.balance
  std::vector<CameraPairRatio> pairRatios_;  // one per seam of the full domain
  std::vector<std::uint8_t> present_;        // per camera, in this set
  std::vector<SeamBlockMeter> meters_;       // one per part of the seam blocks measured at once
  std::vector<float> window_;                // running median along a seam
  std::vector<std::uint8_t> resolve_;        // per region
  std::vector<float> stepScratch_;  // per block of a seam: its step without and with the field
  // CV_32FC3 over fieldStorage_, which has one float past the last block: the vector applies read
  // four floats for a block's three channels.
  std::vector<float> fieldStorage_;
  cv::Mat field_;
  // Upsampling: bicubic weights for each sub-block phase (Catmull-Rom), each pixel column's first
  // tap (in blocks, -2..width), the rows that have anything to correct, and one row buffer per
  // work chunk.
  static constexpr int kPad = 3;
  std::vector<std::array<float, 4>> phaseWeights_;
  std::vector<int> columnTap_;
  std::vector<bool> rowHasShare_;
  std::vector<std::vector<float>> rowBuffers_;
};

}  // namespace surroundd::processing
