// ScanMatcher: a look registered against the world memory before it is fused (thesis §7.2.2):
// the rigid 2-D pose near the odometry's that best lays the look's obstacle evidence onto the
// grid's occupied cells, and how well each direction of it is constrained.
//
// Method (Olson 2009, "Real-time correlative scan matching"; as in Cartographer's
// RealTimeCorrelativeScanMatcher2D, refined as its Ceres matcher does), in bounded units:
//  1. Scan: the look's evidence that backs its free polygon's boundary (what the fusion marks
//     occupied), one point per vertex ray, robot frame; each weighs 1 / (1 + (r / range_scale)²)
//     for the stereo range error, which grows with r².
//  2. Field: around the odometry's pose, a raster of the grid's occupied cells turned into
//     the exact Euclidean distance to the nearest one (Felzenszwalb & Huttenlocher 2012, two
//     separable passes), cut at `truncate_m`, and a score exp(−d² / 2σ²) per cell.
//  3. Search: every rotation in ±angular_window (a step that moves the farthest point by at
//     most a cell) × every whole-cell translation in ±linear_window; the score is the points'
//     weighted mean, times exp(−w(|t|² + θ²)) so that ties go to the odometry. One rotation
//     per unit of work.
//  4. Refine: Gauss–Newton on the bilinear distance field from the best cell (residual: the
//     distance of each point within `truncate_m`, others left out as outliers).
//  5. Constraint: the scan's own surface normals (a line fitted through each point and its
//     neighbours on adjacent rays) give the point-to-line information H = Σ w J Jᵀ,
//     J = (n, n × q) at the result (x, y in m, θ in rad, i.e. metres at 1 m): the map's cells
//     are too coarse for that (gaps between a far wall's hits pull along it). Along an
//     eigenvector of H whose eigenvalue is below `min_information` the scan says nothing (a
//     featureless wall along itself): the correction is projected onto the constrained
//     eigenvectors, so odometry stands along the others (Zhang, Kaess & Singh 2016,
//     "On degeneracy of optimization-based state estimation problems").
// Nothing allocates after construction; the raster and the scan have fixed capacities.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "algo/core/geometry.h"
#include "algo/mapping/star_polygon.h"
#include "algo/worldmap/grid_map.h"

namespace boticelli::worldmap {

inline constexpr int kMatchFieldCells = 256;  // the field's raster a side (12.8 m at 5 cm)
inline constexpr std::size_t kMaxScanPoints = mapping::kMaxPolygonVertices;

struct ScanMatcherParams {
  float linear_window_m = 0.3F;        // the search spans ±this in x and y [m]
  float angular_window_rad = 0.1745F;  // ... and ±this in heading (10°) [rad]
  float max_range_m = 5.0F;            // evidence farther from the look is not matched [m]
  float backing_m = 0.6F;              // only evidence this close beyond the polygon [m]
  float field_sigma_m = 0.10F;         // the search score's width round an occupied cell [m]
  float truncate_m = 0.30F;            // a point farther from any occupied cell is an outlier [m]
  float range_scale_m = 2.0F;          // a point at range r weighs 1 / (1 + (r / this)²) [m]
  float prior_weight = 0.1F;           // tie-break toward odometry [1/m², 1/rad²]
  int refine_iterations = 10;          // Gauss–Newton steps at most
  std::size_t min_points = 20;         // fewer scan points (or occupied cells): no match
  float min_inlier_share = 0.4F;       // of the scan's weight within truncate_m of the map
  float min_information = 5.0F;        // an eigenvalue of H this large constrains [1/m²]
  int normal_neighbours = 3;           // rays each side a point's surface normal is fitted on
  float normal_reach_m = 0.3F;         // ... if they lie this close to the point [m]
  int rows_per_unit = 32;              // raster rows (or columns) per unit of work
};

// What a registration found.
struct Registration {
  bool matched = false;       // enough scan, map and agreement: `pose` is the registered pose
  core::Pose2 initial{};      // where the odometry put the look (mission frame)
  core::Pose2 pose{};         // the registered pose (= initial when not matched)
  core::Pose2 searched{};     // the search's best pose, before refinement and projection
  core::Pose2 refined{};      // the refined pose, before the projection
  float residual_m = 0.0F;    // weighted RMS distance of the inliers at `refined` [m]
  float score = 0.0F;         // the search's best score [0, 1]
  std::size_t points = 0;     // scan points
  std::size_t map_cells = 0;  // occupied cells in the field's raster
  float inlier_share = 0.0F;  // of the scan's weight within truncate_m at `pose`
  // H = JᵀWJ at the result: x, y [m], θ [rad]; its eigenvalues ascending, their vectors as
  // columns, and how many reach min_information.
  Eigen::Matrix3f information = Eigen::Matrix3f::Zero();
  Eigen::Vector3f eigenvalues = Eigen::Vector3f::Zero();
  Eigen::Matrix3f eigenvectors = Eigen::Matrix3f::Identity();
  int constrained = 0;
  std::size_t units = 0;  // units of work it took

  // The information on a translation along the unit vector (ux, uy) [1/m²].
  [[nodiscard]] float information_along(float ux, float uy) const {
    return ux * ux * information(0, 0) + 2.0F * ux * uy * information(0, 1) +
           uy * uy * information(1, 1);
  }
};

class ScanMatcher {
 public:
  ScanMatcher() = default;
  ScanMatcher(const ScanMatcher&) = delete;
  ScanMatcher& operator=(const ScanMatcher&) = delete;

  // A look at `initial` (mission frame, from odometry) with its free polygon and nearest
  // evidence per vertex ray (robot frame, as LookFusion takes them), against `map`. The map
  // must not change until done() (the look is fused after its registration).
  void start(const GridMap& map, const core::Pose2& initial, const mapping::StarPolygon& free,
             const mapping::StarPolygon& evidence, const ScanMatcherParams& params);
  // One unit: raster rows, a distance pass, a rotation of the search, or the refinement.
  // True when done.
  bool run_unit();
  void run() {
    while (!run_unit()) {
    }
  }
  [[nodiscard]] bool done() const { return phase_ == Phase::kDone; }
  [[nodiscard]] const Registration& result() const { return result_; }
  // The scan's points (robot frame) [m].
  [[nodiscard]] std::span<const core::Point2> points() const { return {points_.data(), count_}; }

 private:
  enum class Phase : std::uint8_t { kIdle, kRaster, kColumns, kRows, kSearch, kRefine, kDone };
  static constexpr float kFar = 1e9F;  // no occupied cell in this row or column yet

  void raster_rows();
  void distance_columns();
  void distance_rows();
  void search_rotation();
  void refine();
  // The distance to the nearest occupied cell at world point (x, y) by bilinear interpolation
  // [m], and its gradient; false outside the raster.
  bool distance_at(float x_m, float y_m, float& d_m, float& gx, float& gy) const;
  // H and the weighted inliers at `pose` (no gradient beyond truncate_m).
  void normal_equations(const core::Pose2& pose, Eigen::Matrix3f& h, Eigen::Vector3f& g,
                        float& inlier_weight, float& squares) const;
  // Each point's surface normal from a line through it and its neighbours.
  void fit_normals();
  // The point-to-line information of the scan's normals at `pose`.
  [[nodiscard]] Eigen::Matrix3f surface_information(const core::Pose2& pose) const;
  // The 1-D squared distance transform of f[0..n) (stride `stride` in dist_) in place.
  void transform_line(std::size_t first, std::size_t stride, int n);

  const GridMap* map_ = nullptr;
  ScanMatcherParams params_{};
  Phase phase_ = Phase::kIdle;
  Registration result_{};
  // Scan.
  std::array<core::Point2, kMaxScanPoints> points_{};
  std::array<float, kMaxScanPoints> weights_{};
  std::array<core::Point2, kMaxScanPoints> normals_{};  // robot frame; (0, 0) where none
  std::array<std::uint16_t, kMaxScanPoints> rays_{};    // the vertex ray each point is on
  std::size_t count_ = 0;
  float weight_sum_ = 0.0F;
  // Field raster: cell (i, j) is the grid's (origin_.ix + i, origin_.iy + j).
  Cell origin_{};
  int side_ = 0;
  int line_ = 0;  // the next row or column of the pass under way
  std::array<float, kMatchFieldCells * kMatchFieldCells> dist_{};  // squared cells, then m
  std::array<std::uint8_t, kMatchFieldCells * kMatchFieldCells> score_{};
  // One line of the distance transform.
  std::array<float, kMatchFieldCells> line_f_{};
  std::array<int, kMatchFieldCells> line_v_{};
  std::array<float, kMatchFieldCells + 1> line_z_{};
  // Search.
  int angles_ = 0;
  int angle_ = 0;
  float angle_step_rad_ = 0.0F;
  int shifts_ = 0;  // whole cells each way
  float best_score_ = -1.0F;
  core::Pose2 best_{};
  std::array<int, kMaxScanPoints> cell_i_{};  // a rotation's points at zero shift
  std::array<int, kMaxScanPoints> cell_j_{};
};

}  // namespace boticelli::worldmap
