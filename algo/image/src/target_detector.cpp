// Green-triangle corner detector: colour blobs, shape test, white surround, edge-line vertex.
#include "algo/image/target_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace boticelli::image {

namespace {

// Least-squares line x = a + b·t over (t, x) pairs; returns RMS residual.
struct LineFit {
  double st = 0, sx = 0, stt = 0, stx = 0, sxx = 0;
  int n = 0;
  void add(double t, double x) {
    st += t;
    sx += x;
    stt += t * t;
    stx += t * x;
    sxx += x * x;
    ++n;
  }
  bool solve(double& a, double& b, double& rms) const {
    const double nn = static_cast<double>(n);
    const double det = nn * stt - st * st;
    if (n < 3 || std::fabs(det) < 1e-9) {
      return false;
    }
    b = (nn * stx - st * sx) / det;
    a = (sx - b * st) / nn;
    const double sse =
        sxx - 2.0 * a * sx - 2.0 * b * stx + nn * a * a + 2.0 * a * b * st + b * b * stt;
    rms = std::sqrt(std::max(0.0, sse) / nn);
    return true;
  }
};

float clamp01(float x) {
  return x < 0.0F ? 0.0F : (x > 1.0F ? 1.0F : x);
}

}  // namespace

bool TargetDetector::is_green(const LowResFrame& frame, std::size_t i) const {
  return int{frame.chroma_v[i]} - 128 <= params_.green_max_cr &&
         int{frame.chroma_u[i]} - 128 <= params_.green_max_cb &&
         frame.luma[i] >= params_.green_min_luma;
}

bool TargetDetector::is_white(const LowResFrame& frame, std::size_t i) const {
  return frame.luma[i] >= params_.white_min_luma &&
         std::abs(int{frame.chroma_u[i]} - 128) <= params_.white_max_chroma &&
         std::abs(int{frame.chroma_v[i]} - 128) <= params_.white_max_chroma;
}

TargetDetection TargetDetector::detect(const LowResFrame& frame) {
  TargetDetection best;
  const std::uint32_t w = frame.width;
  const std::uint32_t h = frame.height;
  const std::size_t n = std::size_t{w} * h;
  std::fill(labels_.begin(), labels_.begin() + static_cast<std::ptrdiff_t>(n), 0U);
  std::uint32_t next_label = 0;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (labels_[seed] != 0 || !is_green(frame, seed)) {
      continue;
    }
    // Flood fill (4-connected) with a fixed queue; every pixel enters it at most once.
    const std::uint32_t label = ++next_label;
    std::size_t head = 0;
    std::size_t tail = 0;
    queue_[tail++] = static_cast<std::uint32_t>(seed);
    labels_[seed] = label;
    std::uint32_t u_min = w, u_max = 0, v_min = h, v_max = 0;
    while (head < tail) {
      const std::uint32_t i = queue_[head++];
      const std::uint32_t u = i % w;
      const std::uint32_t v = i / w;
      u_min = std::min(u_min, u);
      u_max = std::max(u_max, u);
      v_min = std::min(v_min, v);
      v_max = std::max(v_max, v);
      const auto visit = [&](std::size_t j) {
        if (labels_[j] == 0 && is_green(frame, j)) {
          labels_[j] = label;
          queue_[tail++] = static_cast<std::uint32_t>(j);
        }
      };
      if (u > 0) visit(i - 1);
      if (u + 1 < w) visit(i + 1);
      if (v > 0) visit(i - w);
      if (v + 1 < h) visit(i + w);
    }
    if (tail < params_.min_area_px) {
      continue;
    }
    const TargetDetection candidate = examine(frame, label, tail, u_min, u_max, v_min, v_max);
    if (candidate.found && candidate.confidence > best.confidence) {
      best = candidate;
    }
  }
  return best;
}

TargetDetection TargetDetector::examine(const LowResFrame& frame, std::uint32_t label,
                                        std::size_t area, std::uint32_t u_min, std::uint32_t u_max,
                                        std::uint32_t v_min, std::uint32_t v_max) {
  TargetDetection out;
  const std::uint32_t w = frame.width;
  const std::uint32_t h = frame.height;
  const std::uint32_t box_w = u_max - u_min + 1;
  const std::uint32_t box_h = v_max - v_min + 1;
  // Not touching the border: a cut triangle has no trustworthy vertex.
  if (u_min == 0 || v_min == 0 || u_max + 1 >= w || v_max + 1 >= h || box_h < 4 || box_w < 4) {
    return out;
  }
  // Equilateral, vertex up: height/width = √3/2 and half the box filled.
  const float aspect = static_cast<float>(box_h) / static_cast<float>(box_w);
  const float fill = static_cast<float>(area) / static_cast<float>(box_w * box_h);
  if (aspect < 0.55F || aspect > 1.3F || fill < 0.3F || fill > 0.7F) {
    return out;
  }
  // Reference green: mean Cr of the blob's interior (pixels whose 4 neighbours are in it).
  double interior_cr = 0.0;
  int interior = 0;
  int darkest_cr = 0;
  for (std::uint32_t v = v_min; v <= v_max; ++v) {
    for (std::uint32_t u = u_min; u <= u_max; ++u) {
      const std::size_t i = frame.index(u, v);
      if (labels_[i] != label) {
        continue;
      }
      const int cr = int{frame.chroma_v[i]} - 128;
      darkest_cr = std::min(darkest_cr, cr);
      if (labels_[i - 1] == label && labels_[i + 1] == label && labels_[i - w] == label &&
          labels_[i + w] == label) {
        interior_cr += cr;
        ++interior;
      }
    }
  }
  const double reference_cr =
      interior > 0 ? interior_cr / interior : static_cast<double>(darkest_cr);
  if (!(reference_cr < 0.0)) {
    return out;
  }
  // Row extents; a hole or a second run in a row breaks the triangle. Edges are sub-pixel:
  // a row's green width is the sum of the coverage Cr/Cr_green of its pixels, centred on
  // their coverage-weighted column (the 4x4 averaging makes coverage proportional to Cr).
  LineFit left;
  LineFit right;
  for (std::uint32_t v = v_min; v <= v_max; ++v) {
    std::int32_t first = -1;
    std::int32_t last = -1;
    std::uint32_t count = 0;
    for (std::uint32_t u = u_min; u <= u_max; ++u) {
      if (labels_[frame.index(u, v)] == label) {
        if (first < 0) first = static_cast<std::int32_t>(u);
        last = static_cast<std::int32_t>(u);
        ++count;
      }
    }
    if (first < 0 || static_cast<std::uint32_t>(last - first + 1) > count + 1) {
      return out;
    }
    // The extreme rows are cut by the pixel grid vertically: only inner rows are fit.
    if (v > v_min && v < v_max) {
      double width = 0.0;
      double moment = 0.0;
      for (std::int32_t u = first - 1; u <= last + 1; ++u) {
        const int cr = int{frame.chroma_v[frame.index(static_cast<std::uint32_t>(u), v)]} - 128;
        const double coverage = std::clamp(static_cast<double>(cr) / reference_cr, 0.0, 1.0);
        width += coverage;
        moment += coverage * u;
      }
      const double centre = moment / width;
      left.add(static_cast<double>(v), centre - 0.5 * width);
      right.add(static_cast<double>(v), centre + 0.5 * width);
    }
  }
  double a_l = 0, b_l = 0, rms_l = 0, a_r = 0, b_r = 0, rms_r = 0;
  if (!left.solve(a_l, b_l, rms_l) || !right.solve(a_r, b_r, rms_r)) {
    return out;
  }
  // Edges of an upright equilateral triangle: du/dv = ∓tan 30° = ∓0.577.
  const double spread = b_r - b_l;
  if (b_l >= 0.0 || b_r <= 0.0 || spread < 0.6 || spread > 1.9) {
    return out;
  }
  const double v_apex = (a_l - a_r) / spread;
  const double u_apex = a_l + b_l * v_apex;
  if (v_apex < static_cast<double>(v_min) - 2.0 || v_apex > static_cast<double>(v_min) + 1.5) {
    return out;
  }
  // White surround: the box grown by a margin, less the triangle itself.
  const std::uint32_t margin = std::max<std::uint32_t>(
      1, static_cast<std::uint32_t>(std::lround(0.15F * static_cast<float>(box_w))));
  const std::uint32_t su0 = u_min > margin ? u_min - margin : 0;
  const std::uint32_t sv0 = v_min > margin ? v_min - margin : 0;
  const std::uint32_t su1 = std::min(w - 1, u_max + margin);
  const std::uint32_t sv1 = std::min(h - 1, v_max + margin);
  std::size_t around = 0;
  std::size_t white = 0;
  for (std::uint32_t v = sv0; v <= sv1; ++v) {
    for (std::uint32_t u = su0; u <= su1; ++u) {
      const std::size_t i = frame.index(u, v);
      if (labels_[i] == label) {
        continue;
      }
      ++around;
      // Mixed pixels at the triangle's edge are neither green nor white: skip them if
      // they touch the triangle.
      const bool touches =
          (u > 0 && labels_[i - 1] == label) || (u + 1 < w && labels_[i + 1] == label) ||
          (v > 0 && labels_[i - w] == label) || (v + 1 < h && labels_[i + w] == label);
      if (touches) {
        --around;
        continue;
      }
      if (is_white(frame, i)) {
        ++white;
      }
    }
  }
  if (around == 0) {
    return out;
  }
  const float white_share = static_cast<float>(white) / static_cast<float>(around);
  if (white_share < params_.min_white_surround) {
    return out;
  }
  const auto residual = static_cast<float>(std::max(rms_l, rms_r));
  const float shape = clamp01(1.0F - std::fabs(static_cast<float>(spread) - 1.155F) / 0.8F);
  const float straight = clamp01(1.0F - residual / 1.5F);
  const float filled = clamp01(1.0F - std::fabs(fill - 0.5F) / 0.3F);
  out.confidence = clamp01(white_share) * (0.4F + 0.6F * shape * straight * filled);
  out.found = out.confidence >= params_.min_confidence;
  out.u_px = static_cast<float>(u_apex);
  out.v_px = static_cast<float>(v_apex);
  out.area_px = area;
  return out;
}

}  // namespace boticelli::image
