// Green-triangle corner detector: chromaticity blobs, shape test, paper surround, edge-line vertex.
#include "algo/image/target_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/Core>

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

// Fits x = a + b·v to one side's row extents x[k] (row v_first + k), from the apex down
// for as long as they stay on one straight line: a base corner ends a side early when the
// triangle is seen rotated (from below or above and aside). The first half of the rows
// (at least three) is taken as the side; later rows join while within this of the line.
constexpr double kCornerTolerance_px = 0.4;

bool fit_side(const double* x, std::uint32_t v_first, std::uint32_t rows, double& a, double& b,
              double& rms) {
  const std::uint32_t start = std::min(rows, std::max<std::uint32_t>(3, (rows + 1) / 2));
  LineFit fit;
  for (std::uint32_t k = 0; k < start; ++k) {
    fit.add(static_cast<double>(v_first + k), x[k]);
  }
  if (!fit.solve(a, b, rms)) {
    return false;
  }
  for (std::uint32_t k = start; k < rows; ++k) {
    const double t = static_cast<double>(v_first + k);
    if (std::fabs(x[k] - (a + b * t)) > kCornerTolerance_px) {
      break;
    }
    fit.add(t, x[k]);
    fit.solve(a, b, rms);
  }
  return true;
}

float clamp01(float x) {
  return x < 0.0F ? 0.0F : (x > 1.0F ? 1.0F : x);
}

// Quantisation of the averaged chroma: a grey pixel can read ±1 level off neutral.
constexpr float kChromaQuantum = 2.0F;

}  // namespace

float target_confidence(float white_share, float residual_px, float fill, float skew) {
  const float straight = clamp01(1.0F - residual_px / 1.5F);
  const float filled = clamp01(1.0F - std::fabs(fill - 0.5F) / 0.3F);
  const float symmetric = clamp01(1.0F - skew / 0.6F);
  return clamp01(white_share) * (0.4F + 0.6F * straight * filled * (0.5F + 0.5F * symmetric));
}

bool TargetDetector::is_green(const LowResFrame& frame, std::size_t i, bool seed) const {
  const float cr = static_cast<float>(int{frame.chroma_v[i]} - 128);
  const float cb = static_cast<float>(int{frame.chroma_u[i]} - 128);
  const float bright = std::max(0.0F, frame.luma[i] - params_.black_luma);
  if (seed) {
    return -cr >= params_.seed_min_chroma && -cr >= params_.seed_min_cr_ratio * bright &&
           -cb >= params_.seed_min_cb_ratio * bright;
  }
  return -cr >= params_.grow_min_chroma && -cr >= params_.grow_min_cr_ratio * bright &&
         -cb >= params_.grow_min_cb_ratio * bright;
}

TargetDetection TargetDetector::detect(const LowResFrame& frame) {
  TargetDetection best;
  const std::uint32_t w = frame.width;
  const std::uint32_t h = frame.height;
  const std::size_t n = std::size_t{w} * h;
  std::fill(labels_.begin(), labels_.begin() + static_cast<std::ptrdiff_t>(n), 0U);
  std::uint32_t next_label = 0;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (labels_[seed] != 0 || !is_green(frame, seed, true)) {
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
        if (labels_[j] == 0 && is_green(frame, j, false)) {
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
  if (u_min == 0 || v_min == 0 || u_max + 1 >= w || v_max + 1 >= h || box_h < 5 || box_w < 3) {
    return out;
  }
  // Equilateral, vertex up, seen from up to ~60° aside: height/width from √3/2 (head-on) to
  // √3 (60° off the normal), and half the box filled whatever the foreshortening.
  const float aspect = static_cast<float>(box_h) / static_cast<float>(box_w);
  const float fill = static_cast<float>(area) / static_cast<float>(box_w * box_h);
  if (aspect < 0.55F || aspect > 2.4F || fill < 0.3F || fill > 0.75F) {
    return out;
  }
  // Reference green: mean chroma and luma of the blob's interior (pixels whose 4 neighbours
  // are in it); a blob too thin for an interior uses its greenest pixel.
  const auto inner = [&](std::size_t i) {
    return labels_[i - 1] == label && labels_[i + 1] == label && labels_[i - w] == label &&
           labels_[i + w] == label;
  };
  double sum_cb = 0.0, sum_cr = 0.0, sum_y = 0.0;
  int interior = 0;
  std::size_t greenest = frame.index(u_min, v_min);
  for (std::uint32_t v = v_min; v <= v_max; ++v) {
    for (std::uint32_t u = u_min; u <= u_max; ++u) {
      const std::size_t i = frame.index(u, v);
      if (labels_[i] != label) {
        continue;
      }
      if (labels_[greenest] != label || frame.chroma_v[i] < frame.chroma_v[greenest]) {
        greenest = i;
      }
      if (inner(i)) {
        sum_cb += int{frame.chroma_u[i]} - 128;
        sum_cr += int{frame.chroma_v[i]} - 128;
        sum_y += static_cast<double>(frame.luma[i]);
        ++interior;
      }
    }
  }
  const bool thin = interior == 0;
  if (thin) {
    sum_cb = int{frame.chroma_u[greenest]} - 128;
    sum_cr = int{frame.chroma_v[greenest]} - 128;
    sum_y = static_cast<double>(frame.luma[greenest]);
    interior = 1;
  }
  const double green_cb = sum_cb / interior;
  const double green_cr = sum_cr / interior;
  const double green_bright = sum_y / interior - static_cast<double>(params_.black_luma);
  // Paper around it: the box grown by a margin (15% of its size each way), less the
  // triangle and the mixed pixels touching it. White = brighter than the green by the
  // configured ratio and grey for its brightness; their mean chroma is the neutral.
  const auto grow = [](std::uint32_t size) {
    return std::max<std::uint32_t>(1, static_cast<std::uint32_t>(std::lround(0.15 * size)));
  };
  const std::uint32_t mu = grow(box_w);
  const std::uint32_t mv = grow(box_h);
  const std::uint32_t su0 = u_min > mu ? u_min - mu : 0;
  const std::uint32_t sv0 = v_min > mv ? v_min - mv : 0;
  const std::uint32_t su1 = std::min(w - 1, u_max + mu);
  const std::uint32_t sv1 = std::min(h - 1, v_max + mv);
  const double white_min_bright =
      std::max(1.0, static_cast<double>(params_.white_min_luma_ratio) * green_bright);
  std::size_t around = 0;
  std::size_t white = 0;
  double white_y = 0.0;
  double white_cb = 0.0;
  double white_cr = 0.0;
  // Normal equations of the paper's brightness as a plane over the image, a + b·du + c·dv
  // (du, dv from the box's centre): vignetting and uneven light darken the paper across
  // the triangle, and a single mean would bias the edges on the side it darkens.
  const double uc = 0.5 * static_cast<double>(u_min + u_max);
  const double vc = 0.5 * static_cast<double>(v_min + v_max);
  Eigen::Matrix3d plane_ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d plane_atb = Eigen::Vector3d::Zero();
  for (std::uint32_t v = sv0; v <= sv1; ++v) {
    for (std::uint32_t u = su0; u <= su1; ++u) {
      const std::size_t i = frame.index(u, v);
      if (labels_[i] == label) {
        continue;
      }
      const bool touches =
          (u > 0 && labels_[i - 1] == label) || (u + 1 < w && labels_[i + 1] == label) ||
          (v > 0 && labels_[i - w] == label) || (v + 1 < h && labels_[i + w] == label);
      if (touches) {
        continue;
      }
      ++around;
      const double bright = static_cast<double>(frame.luma[i] - params_.black_luma);
      const int cb = int{frame.chroma_u[i]} - 128;
      const int cr = int{frame.chroma_v[i]} - 128;
      const double grey_limit =
          std::max(static_cast<double>(kChromaQuantum),
                   static_cast<double>(params_.white_max_chroma_ratio) * bright);
      if (bright >= white_min_bright && std::abs(cb) <= grey_limit && std::abs(cr) <= grey_limit) {
        ++white;
        white_y += bright;
        white_cb += cb;
        white_cr += cr;
        const Eigen::Vector3d x(1.0, static_cast<double>(u) - uc, static_cast<double>(v) - vc);
        plane_ata += x * x.transpose();
        plane_atb += bright * x;
      }
    }
  }
  if (around == 0 || white == 0) {
    return out;
  }
  const float white_share = static_cast<float>(white) / static_cast<float>(around);
  if (white_share < params_.min_white_surround) {
    return out;
  }
  white_y /= static_cast<double>(white);
  white_cb /= static_cast<double>(white);
  white_cr /= static_cast<double>(white);
  // Coverage of a pixel by the triangle: where its luma lies from the paper's (0) to the
  // interior's (1); the 4x4 averaging mixes linearly, and the averaged luma is not rounded
  // (the chroma is, to whole levels, which biases edges by up to ~0.1 px with the phase and
  // put ~0.15 m of bias into a pair's range at 1.5 m). Pixels must be greener than the paper.
  const double dcb = green_cb - white_cb;
  const double dcr = green_cr - white_cr;
  const double contrast2 = dcb * dcb + dcr * dcr;
  if (contrast2 < 9.0) {
    return out;
  }
  const double luma_contrast = white_y - green_bright;
  if (luma_contrast < 3.0) {
    return out;
  }
  // The paper's plane; the mean alone when the white pixels do not span one (a sliver).
  Eigen::Vector3d paper(white_y, 0.0, 0.0);
  // (The determinant is n³ times the white pixels' variances across and along, less their
  // covariance: at least a tenth of a pixel² each way.)
  const double n_white = plane_ata(0, 0);
  if (plane_ata.determinant() > 0.01 * n_white * n_white * n_white) {
    const Eigen::Vector3d fitted = plane_ata.ldlt().solve(plane_atb);
    if (fitted.allFinite()) paper = fitted;
  }
  const auto paper_at = [&](std::uint32_t u, std::uint32_t v) {
    return paper.x() + paper.y() * (static_cast<double>(u) - uc) +
           paper.z() * (static_cast<double>(v) - vc);
  };
  // The green's share of the paper's brightness: light and vignetting scale both alike.
  double green_share = 0.0;
  int shares = 0;
  for (std::uint32_t v = v_min; v <= v_max; ++v) {
    for (std::uint32_t u = u_min; u <= u_max; ++u) {
      const std::size_t i = frame.index(u, v);
      if (labels_[i] != label || (thin ? i != greenest : !inner(i))) {
        continue;
      }
      const double local = paper_at(u, v);
      if (local > 1.0) {
        green_share += static_cast<double>(frame.luma[i] - params_.black_luma) / local;
        ++shares;
      }
    }
  }
  if (shares == 0) {
    return out;
  }
  green_share /= shares;
  if (!(green_share < 1.0 - 3.0 / white_y)) {
    return out;
  }
  const auto coverage = [&](std::size_t i) {
    const double cb = int{frame.chroma_u[i]} - 128 - white_cb;
    const double cr = int{frame.chroma_v[i]} - 128 - white_cr;
    if (!(cb * dcb + cr * dcr > 0.0)) {
      return 0.0;  // not greener than the paper: a dark edge or shadow, not the triangle
    }
    const double bright = static_cast<double>(frame.luma[i] - params_.black_luma);
    const double local =
        paper_at(static_cast<std::uint32_t>(i % w), static_cast<std::uint32_t>(i / w));
    if (!(local > 1.0)) {
      return 0.0;
    }
    return std::clamp((1.0 - bright / local) / (1.0 - green_share), 0.0, 1.0);
  };
  // Row extents; a hole or a second run in a row breaks the triangle. Edges are sub-pixel:
  // a row's green width is the sum of its pixels' coverage, centred on their
  // coverage-weighted column, over the run and two pixels either side (not other blobs).
  std::uint32_t rows = 0;
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
      const std::int32_t from = std::max<std::int32_t>(0, first - 2);
      const std::int32_t to = std::min<std::int32_t>(static_cast<std::int32_t>(w) - 1, last + 2);
      for (std::int32_t u = from; u <= to; ++u) {
        const std::size_t i = frame.index(static_cast<std::uint32_t>(u), v);
        if (labels_[i] != label && labels_[i] != 0) {
          continue;
        }
        const double c = coverage(i);
        width += c;
        moment += c * u;
      }
      if (!(width > 0.0)) {
        return out;
      }
      const double centre = moment / width;
      row_left_[rows] = centre - 0.5 * width;
      row_right_[rows] = centre + 0.5 * width;
      ++rows;
    }
  }
  double a_l = 0, b_l = 0, rms_l = 0, a_r = 0, b_r = 0, rms_r = 0;
  if (!fit_side(row_left_.data(), v_min + 1, rows, a_l, b_l, rms_l) ||
      !fit_side(row_right_.data(), v_min + 1, rows, a_r, b_r, rms_r)) {
    return out;
  }
  // Edges of an upright equilateral triangle: du/dv = ∓tan 30° = ∓0.577 head-on, half that
  // at 60° aside, steeper when seen from below or above; the apex above the base's middle.
  const double spread = b_r - b_l;
  if (b_l >= 0.0 || b_r <= 0.0 || spread < 0.45 || spread > 2.0) {
    return out;
  }
  const double skew = std::fabs(b_l + b_r) / spread;
  if (skew > 0.6) {
    return out;
  }
  const double v_apex = (a_l - a_r) / spread;
  const double u_apex = a_l + b_l * v_apex;
  if (v_apex < static_cast<double>(v_min) - 2.0 || v_apex > static_cast<double>(v_min) + 1.5) {
    return out;
  }
  out.confidence = target_confidence(white_share, static_cast<float>(std::max(rms_l, rms_r)), fill,
                                     static_cast<float>(skew));
  out.found = out.confidence >= params_.min_confidence;
  out.u_px = static_cast<float>(u_apex);
  out.v_px = static_cast<float>(v_apex);
  out.area_px = area;
  out.box_u_min = u_min;
  out.box_u_max = u_max;
  out.box_v_min = v_min;
  out.box_v_max = v_max;
  return out;
}

}  // namespace boticelli::image
