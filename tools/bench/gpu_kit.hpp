#pragma once
// What surround-gpu-check (tools/gpu_check) measures, packed for a machine that has a GPU but
// none of the libraries that decode recordings or read rigs: per recording, its panorama LUT (the
// daemon's bowl projection, in the LUT cache's file format) and its first ground-truth frame set
// as a YUYV camera would deliver it, raw.
//
//   KIT/<recording's name>/panorama.lut
//   KIT/<recording's name>/camera<i>.yuyv   (the LUT says each one's size)

#include <filesystem>

namespace surroundd {
class WorkPool;
}

namespace surroundd::bench {

// Throws std::runtime_error naming what could not be read or written.
void writeGpuKit(const std::filesystem::path& recording, const std::filesystem::path& kit,
                 WorkPool& pool);

}  // namespace surroundd::bench
