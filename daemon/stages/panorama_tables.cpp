#include "daemon/stages/panorama_tables.hpp"

#include <utility>

#include <spdlog/spdlog.h>

#include "daemon/config/panorama_setup.hpp"
#include "daemon/pipeline_ends.hpp"

namespace surroundd::daemon {

PanoramaTables::PanoramaTables(const Config& config, processing::Rig mounted, WorkPool& build,
                               WorkPool& pool)
    : rig(std::move(mounted)),
      lut(obtainPanoramaLut(config, rig, build)),
      stitcher(lut, pool),
      ownership(lut) {
  const processing::ColourCorrectionSettings& settings = config.colour.poisson;
  if (config.colour.method == ColourMethod::kGain) {
    gains = std::make_unique<processing::GainCompensation>(lut, pool, settings.minGain,
                                                           settings.maxGain, cameraNames(config));
    spdlog::info("colour correction: global gain compensation");
  } else if (config.colour.method == ColourMethod::kPoisson) {
    poisson = std::make_unique<processing::PoissonColourCorrection>(rig, panoramaSettings(config),
                                                                    lut, settings, pool);
    for (const auto& note : poisson->notes()) spdlog::warn("colour correction: {}", note);
    spdlog::info("colour correction: Poisson, {} region(s) at scale {:g}, solver {}",
                 poisson->domain().regions.size(), settings.scale, poisson->solverNames());
  }
}

}  // namespace surroundd::daemon
