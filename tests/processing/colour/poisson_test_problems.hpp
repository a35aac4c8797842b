#pragma once
// Poisson systems drawn for the solver tests: a canvas of unknowns, Dirichlet pixels with their
// values and outside (Neumann) pixels, turned into a PoissonSystem and its right-hand sides the
// way the correction domain builder does it.

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/colour/poisson_system.hpp"

namespace surroundd::processing::testing {

enum class Cell : char { kOutside, kUnknown, kDirichlet };

// A drawing of a region: unknowns, Dirichlet pixels with their values (8-bit levels, per
// channel), and outside pixels (Neumann borders).
struct Canvas {
  cv::Size size;
  std::vector<Cell> cells;
  std::vector<cv::Vec3f> values;

  Canvas(cv::Size s, Cell fill)
      : size(s), cells(static_cast<std::size_t>(s.area()), fill), values(cells.size()) {}
  std::size_t index(int x, int y) const { return static_cast<std::size_t>(y) * size.width + x; }
  Cell& at(int x, int y) { return cells[index(x, y)]; }
  Cell at(int x, int y) const {
    if (x < 0 || y < 0 || x >= size.width || y >= size.height) return Cell::kOutside;
    return cells[index(x, y)];
  }
};

struct Problem {
  PoissonSystem system;
  ChannelValues rhs;
  std::size_t leftOut = 0;  // unknowns in parts that no Dirichlet pixel reaches
};

// What the domain builder does: parts of the region without a Dirichlet neighbour are left out;
// the rest, in row-major order in its bounding box, with degrees, links and right-hand sides.
inline Problem buildProblem(const Canvas& canvas) {
  std::vector<int> part(canvas.cells.size(), -1);
  std::vector<bool> partTouchesSeam;
  for (int y = 0; y < canvas.size.height; ++y) {
    for (int x = 0; x < canvas.size.width; ++x) {
      if (canvas.at(x, y) != Cell::kUnknown || part[canvas.index(x, y)] >= 0) continue;
      const int label = static_cast<int>(partTouchesSeam.size());
      partTouchesSeam.push_back(false);
      std::vector<cv::Point> stack{{x, y}};
      part[canvas.index(x, y)] = label;
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        for (const cv::Point d :
             {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
          const cv::Point q = p + d;
          if (canvas.at(q.x, q.y) == Cell::kDirichlet) partTouchesSeam.back() = true;
          if (canvas.at(q.x, q.y) == Cell::kUnknown && part[canvas.index(q.x, q.y)] < 0) {
            part[canvas.index(q.x, q.y)] = label;
            stack.push_back(q);
          }
        }
      }
    }
  }
  Problem problem;
  cv::Rect frame;
  std::vector<cv::Point> kept;
  for (int y = 0; y < canvas.size.height; ++y) {
    for (int x = 0; x < canvas.size.width; ++x) {
      const int label = part[canvas.index(x, y)];
      if (label < 0) continue;
      if (!partTouchesSeam[static_cast<std::size_t>(label)]) {
        ++problem.leftOut;
        continue;
      }
      frame = kept.empty() ? cv::Rect(x, y, 1, 1) : (frame | cv::Rect(x, y, 1, 1));
      kept.emplace_back(x, y);
    }
  }
  std::vector<int> unknownOf(canvas.cells.size(), -1);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    unknownOf[canvas.index(kept[i].x, kept[i].y)] = static_cast<int>(i);
  }
  PoissonSystem& system = problem.system;
  system.size = frame.size();
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const cv::Point p = kept[i];
    system.pixels.push_back(p - frame.tl());
    int degree = 0;
    cv::Vec3f sum(0, 0, 0);
    for (const cv::Point d :
         {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
      const cv::Point q = p + d;
      const Cell cell = canvas.at(q.x, q.y);
      if (cell == Cell::kDirichlet) {
        ++degree;
        sum += canvas.values[canvas.index(q.x, q.y)];
      } else if (cell == Cell::kUnknown && unknownOf[canvas.index(q.x, q.y)] >= 0) {
        ++degree;
        const int j = unknownOf[canvas.index(q.x, q.y)];
        if (static_cast<int>(i) < j) system.links.emplace_back(static_cast<int>(i), j);
      }
    }
    system.degree.push_back(degree);
    for (int c = 0; c < 3; ++c) problem.rhs.push_back(sum[c]);
  }
  return problem;
}

// Seam values of 0..60 levels, smooth along the seam with some noise on top.
inline void fillSeams(Canvas& canvas, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> noise(-3.0f, 3.0f);
  for (int y = 0; y < canvas.size.height; ++y) {
    for (int x = 0; x < canvas.size.width; ++x) {
      if (canvas.at(x, y) != Cell::kDirichlet) continue;
      for (int c = 0; c < 3; ++c) {
        const float smooth =
            30.0f + 25.0f * std::sin(0.07f * static_cast<float>(y + 3 * x) + static_cast<float>(c));
        canvas.values[canvas.index(x, y)][c] = std::clamp(smooth + noise(random), 0.0f, 60.0f);
      }
    }
  }
}

// W x H unknowns, seams along the whole left and right columns (what fixed azimuths give).
inline Canvas rectangleCanvas(cv::Size size, unsigned seed = 1) {
  Canvas canvas({size.width + 2, size.height}, Cell::kUnknown);
  for (int y = 0; y < size.height; ++y) {
    canvas.at(0, y) = Cell::kDirichlet;
    canvas.at(size.width + 1, y) = Cell::kDirichlet;
  }
  fillSeams(canvas, seed);
  return canvas;
}

// The rectangle with holes, an uneven bottom edge, rows whose left seam is missing, and a seam
// piece along part of the top.
inline Canvas irregularCanvas(cv::Size size) {
  Canvas canvas = rectangleCanvas(size);
  for (int x = 1; x <= size.width; ++x) {
    const int depth = static_cast<int>(4 + 3 * std::sin(0.3 * x));  // uneven bottom edge
    for (int y = size.height - depth; y < size.height; ++y) canvas.at(x, y) = Cell::kOutside;
  }
  for (int y = 5; y < 9; ++y) canvas.at(0, y) = Cell::kOutside;  // no seam on these rows
  for (int y = 12; y < 16; ++y) {                                // a hole
    for (int x = size.width / 3; x < size.width / 3 + 5; ++x) canvas.at(x, y) = Cell::kOutside;
  }
  for (int x = size.width / 2; x < size.width / 2 + 6; ++x) canvas.at(x, 0) = Cell::kDirichlet;
  fillSeams(canvas, 7);
  return canvas;
}

// Frame to frame the seams drift: b' from seam values * gain + noise.
inline ChannelValues driftedRhs(Canvas canvas, float gain, float noise, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<float> normal(0.0f, noise);
  for (auto& value : canvas.values) {
    for (int c = 0; c < 3; ++c) value[c] = value[c] * gain + normal(random);
  }
  return buildProblem(canvas).rhs;
}

}  // namespace surroundd::processing::testing
