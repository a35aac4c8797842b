#pragma once
// What the panorama is made with for one set of the cameras' mounts: its look-up table (built, or
// read from the cache), the stitch and the cameras' ownership over it, and the colour correction
// set up on it (Poisson or gain compensation, as colour_correction says). Built at start-up, and
// again beside the sets for mounts corrected from the road (PanoramaStage::remount()).

#include <memory>

#include "common/work_pool.hpp"
#include "daemon/config/config.hpp"
#include "processing/colour/gain_compensation.hpp"
#include "processing/colour/poisson_correction.hpp"
#include "processing/rig.hpp"
#include "processing/stitch/panorama_lut.hpp"
#include "processing/stitch/panorama_ownership.hpp"
#include "processing/stitch/stitcher.hpp"

namespace surroundd::daemon {

struct PanoramaTables {
  // For the cameras of `mounted` (their body masks included): the heavy work of the build on
  // `build`, the per-set work of what it makes on `pool` (the two differ where the build goes on
  // beside the sets, which `pool` serves). Logs the colour correction's set-up. Throws
  // std::runtime_error naming the config for a rig that cannot make a panorama.
  PanoramaTables(const Config& config, processing::Rig mounted, WorkPool& build, WorkPool& pool);
  PanoramaTables(const PanoramaTables&) = delete;
  PanoramaTables& operator=(const PanoramaTables&) = delete;

  processing::Rig rig;
  processing::PanoramaLut lut;
  processing::Stitcher stitcher;  // borrows lut
  processing::PanoramaOwnership ownership;
  std::unique_ptr<processing::PoissonColourCorrection> poisson;  // colour_correction: poisson
  std::unique_ptr<processing::GainCompensation> gains;           // colour_correction: gain
};

}  // namespace surroundd::daemon
