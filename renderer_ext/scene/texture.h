// Textures: colour as a function of surface coordinates (u, v) in [0, 1]^2.
#pragma once

#include <cmath>
#include <vector>

#include "core/vec3.h"

namespace wv {

enum class TextureKind { kConstant, kChecker, kGrid, kImage };

struct Texture {
  TextureKind kind = TextureKind::kConstant;
  V3 a{1, 1, 1}, b{0, 0, 0}, c{0, 0, 0};  // constant: a; checker: a, b; grid: base a, u-lines b, v-lines c
  double su = 1, sv = 1;                   // checker: checks; grid: cells; image: repeats
  double width = 0.0;                      // grid line width (fraction of a cell)
  // grid: line number k = 0 .. cells of constant u (v) drawn in mark_u_color (mark_v_color); -1: none
  int mark_u = -1, mark_v = -1;
  V3 mark_u_color{0, 0, 0}, mark_v_color{0, 0, 0};
  int w = 0, h = 0;                        // image size
  std::vector<float> rgb;                  // image, row 0 at v = 1

  V3 eval(double u, double v) const {
    switch (kind) {
      case TextureKind::kConstant: return a;
      case TextureKind::kChecker: {
        const long i = long(std::floor(u * su)), j = long(std::floor(v * sv));
        return ((i + j) & 1) ? b : a;
      }
      case TextureKind::kGrid: {
        const double fu = u * su - std::floor(u * su), fv = v * sv - std::floor(v * sv);
        const double hw = 0.5 * width;
        // Line k of constant u lies at u = k / su; the nearest one's number is round(u su).
        if (fv < hw || fv > 1.0 - hw)  // horizontal line: constant v
          return long(std::lround(v * sv)) == mark_v ? mark_v_color : c;
        if (fu < hw || fu > 1.0 - hw)  // vertical line: constant u
          return long(std::lround(u * su)) == mark_u ? mark_u_color : b;
        return a;
      }
      case TextureKind::kImage: return image(u * su, v * sv);
    }
    return a;
  }

  // Bilinear lookup with wrap-around.
  V3 image(double u, double v) const {
    const double x = (u - std::floor(u)) * w - 0.5, y = (1.0 - (v - std::floor(v))) * h - 0.5;
    const long x0 = long(std::floor(x)), y0 = long(std::floor(y));
    const double fx = x - x0, fy = y - y0;
    auto px = [&](long i, long j) {
      i = ((i % w) + w) % w;
      j = std::min<long>(std::max<long>(j, 0), h - 1);
      const float* p = &rgb[3 * (size_t(j) * w + size_t(i))];
      return V3{p[0], p[1], p[2]};
    };
    return (px(x0, y0) * (1 - fx) + px(x0 + 1, y0) * fx) * (1 - fy) +
           (px(x0, y0 + 1) * (1 - fx) + px(x0 + 1, y0 + 1) * fx) * fy;
  }
};

}  // namespace wv
