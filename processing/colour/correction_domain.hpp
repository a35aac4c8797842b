#pragma once
// Where Poisson local colour correction works, built once from the rig and the panorama LUT.
//
// The panorama is divided into blocks of `block` x `block` pixels (scale = 1 / block), each owned
// by the camera that owns its centre pixel. Each connected set of blocks owned by one source
// camera is a region with its own PoissonSystem. A block across a 4-neighbour border that a
// target camera owns, and that the source camera sees too, is a Dirichlet block: its value comes
// from the block's pixels that both cameras see, sampled through taps built here. Only pixels that
// neither camera's body mask hides take part (the projector leaves those out) and, with
// `groundSeams` on a bowl, only the ground: on a real rig the wall part of a seam sees different
// things from the two cameras (parallax), the ground the same. So a pixel on the floor is sampled
// where the bowl puts it, and a pixel on the wall whose ray points at least 1 degree below the
// horizon is sampled where that ray meets the ground (the far ground, its own band: Dirichlet
// blocks marked `beyondFloor`); pixels nearer the horizon or above it give no seam data. Every
// other border is Neumann. A region with no Dirichlet block cannot be corrected (nothing to match)
// and is left out, with a note saying so. The Dirichlet blocks a region shares with one target
// camera form a seam, listed along its length for the robust statistics of poisson_correction.hpp.
//
// For applying the fields: `share` gives each panorama pixel the weight of source cameras in it
// (1 inside a source region, the blend weight in the seam bands), and `fillFrom` says which field
// value each block shows, extended two blocks past every region so that bicubic upsampling has
// data on both sides of its border.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/colour/poisson_system.hpp"
#include "processing/stitch/panorama_lut.hpp"

namespace surroundd::processing {

struct SeamSample {
  LutTap target;
  LutTap source;
};

struct DirichletBlock {
  int block = 0;                                 // index in the block grid
  std::uint8_t target = 0;                       // the camera across the seam
  std::uint32_t firstSample = 0, endSample = 0;  // range in CorrectionDomain::samples
  bool beyondFloor = false;  // ground seam data from past the bowl's floor (the far ground)
};

struct CorrectionRegion {
  std::uint8_t source = 0;
  PoissonSystem system;
  std::vector<int> blockOfUnknown;
  std::vector<DirichletBlock> dirichlet;
  // Per unknown, its Dirichlet neighbours: dirichletOf[dirichletBegin[i] .. dirichletBegin[i+1]).
  std::vector<std::uint32_t> dirichletBegin;
  std::vector<std::uint32_t> dirichletOf;
  // Per Dirichlet block, the unknowns next to it: unknownsOf[unknownsBegin[k] .. [k+1]).
  std::vector<std::uint32_t> unknownsBegin;
  std::vector<std::uint32_t> unknownsOf;
};

// The Dirichlet blocks of one region towards one target camera, in order along the seam.
struct CorrectionSeam {
  std::uint32_t region = 0;  // index in CorrectionDomain::regions
  std::uint8_t target = 0;
  std::vector<std::uint32_t> blocks;  // indices into the region's dirichlet
};

struct CorrectionDomain {
  int block = 4;
  cv::Size grid;  // blocks; columns wrap around like the panorama's
  std::vector<CorrectionRegion> regions;
  std::vector<CorrectionSeam> seams;
  std::vector<SeamSample> samples;
  // Field slots: the unknowns of every region, in order, then their Dirichlet blocks.
  std::size_t slots = 0;
  std::vector<std::uint32_t> firstUnknownSlot;    // per region
  std::vector<std::uint32_t> firstDirichletSlot;  // per region
  std::vector<int> fillFrom;         // per block: the slot it shows, or -1 (no correction)
  std::vector<std::uint16_t> share;  // per panorama pixel: source weight, 0..256
  std::vector<bool> sourceCameras;   // per camera: a source (corrected) or a target
  std::vector<std::string> notes;    // what was left out and why, for the log
};

// The field is solved on blocks of 1 / scale pixels, which must tile the panorama: the block's
// side, or none when `scale` is not 1/N with N dividing both of `panorama`'s sides. The one rule
// for the config's check and for buildCorrectionDomain's.
std::optional<int> correctionBlock(double scale, cv::Size panorama);
// Why correctionBlock() has none: "must be 1/N with N dividing the panorama's 2048x1024 pixels
// (e.g. 0.25 or 0.125), got 0.3".
std::string correctionBlockProblem(double scale, cv::Size panorama);

// `present` (per camera; empty: all) leaves out missing cameras: a missing source's regions, and
// the seams with a missing target, which become Neumann borders. Throws std::invalid_argument for
// a scale that correctionBlock() refuses.
CorrectionDomain buildCorrectionDomain(const Rig& rig, const PanoramaSettings& settings,
                                       const PanoramaLut& lut, double scale, bool groundSeams,
                                       std::span<const bool> present = {});

}  // namespace surroundd::processing
