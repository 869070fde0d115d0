// Think stage of one look: readings → ray samples → ALN fit → feature guard → navigation polygon,
// resumable in small units of work.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "algo/aln/aln.h"
#include "algo/aln/samples.h"
#include "algo/aln/trainer.h"
#include "algo/core/fixed_vector.h"
#include "algo/evidence/ray_samples.h"
#include "algo/evidence/reading.h"
#include "algo/mapping/aln_free_range.h"
#include "algo/mapping/extraction.h"
#include "algo/mapping/feature_guard.h"
#include "algo/mapping/map_points.h"
#include "algo/mapping/star_polygon.h"

namespace boticelli::mapping {

inline constexpr std::size_t kLookMaxPieces = 256;
// Ray samples of one look: 5 per reading for up to ~24k readings and floor rays, plus the
// seam copies (§4.9.1).
inline constexpr std::size_t kLookMaxSamples = 196608;

using OccupancyModel = aln::Aln<float, 3, kLookMaxPieces>;
// The mission splits by the V (TrainerConfig::split, docs/architecture.md): no hinge sums.
using OccupancyTrainer = aln::Trainer<float, 3, kLookMaxPieces, 0>;
using OccupancySample = aln::Sample<float, 3>;

// Everything the Think stage of one look needs, in one place (the mission derives it from the
// board config once).
struct LocalModelParams {
  ExtractionParams extraction;     // slices, m_safe, bounding circle, robot radius
  evidence::RaySampleParams rays;  // Fig 4.2b samples per reading
  aln::TrainerConfig trainer;      // ε, piece cap, rounds (§4.7.3)
  FeatureGuardParams guard;        // features the fit misses
  float model_lowest_h_m = -0.7F;  // the model's input box: heights relative to the PTU
  float model_highest_h_m = 1.9F;  //   centre [m] and ranges [m] (ReadingLimits)
  float model_max_range_m = 5.4F;
  float seam_margin_rad = 0.5F;  // α copies beyond [0, 2π) (§4.9.1)
  // Free samples (occupancy 0) on the line of sight to each floor point seen free, at these
  // fractions of its range: the floor cue's positive evidence of free space.
  std::size_t free_samples_per_ray = 4;
  // Only space something showed free counts as free (§4.9.1: unknown is not free): the free
  // polygon is cut to the farthest floor seen in each vertex direction.
  bool clamp_to_seen_free = true;
  // With the floor cue's walk starts (start()'s floor_free_near), floor counts as seen only
  // along walks joined to the robot: one that starts within seen_floor_start_m of the PTU
  // axis (the floor nearer than the lowest view's bottom row is never in view, whatever the
  // robot does) or at most seen_floor_gap_m beyond where a joined walk in the same vertex
  // direction ends. A walk that starts beyond an obstacle (a high view over a low box)
  // shows nothing about the floor before it.
  float seen_floor_start_m = 0.7F;
  float seen_floor_gap_m = 0.1F;
  // A walk blocked at the lowest view's bottom row (start()'s floor_blocked) closes its vertex
  // ray: at evidence of an obstacle on it before the row (a base, a guard point, a
  // band feature), else where the ray leaves the free polygon of an earlier look (start()'s
  // prior: that look saw the space before it free, and the obstacle stands still), else to
  // the robot's own disc. false: blocked walks are ignored. docs/mapping.md.
  bool close_blocked_rays = true;
  // A stereo feature in the robot's height band (m ≥ m_safe) counts the band as seen free up
  // to 2 δr before it. Its line of sight is free, but not the floor under it: a box lower
  // than the line of sight stays unseen. false: only the floor cue shows the floor free.
  bool features_show_free = true;
  // Wedges of the free polygon narrower than 2·spike_half_width + 1 vertex rays are cut to
  // their neighbours (open_spikes): a ray or two the fit leaves open through a wall, or that a
  // stray far reading kept seen. 0 keeps them (the first wave's polygon).
  std::size_t spike_half_width = 0;
  // A floor-cue obstacle base cuts the polygon's vertex ray this much in front of it [m].
  float base_margin_m = 0.05F;
  // A guard point (a corroborated feature the fit calls free) stands for a patch of surface,
  // not a point: with guard_disc_m > 0 the polygon is pulled in front of a disc of this
  // radius around it [m], so the rays between two features of a textured obstacle are cut
  // too (exclude_discs). 0 (the default) pulls in front of the point only; docs/mapping.md
  // has what 0.05 m gained and cost.
  float guard_disc_m = 0.0F;
  std::size_t readings_per_unit = 64;           // work per unit while building samples
  std::size_t visits_per_unit = 1024;           // trainer sample visits per unit
  std::size_t guard_candidates_per_unit = 256;  // guard candidates corroborated per unit
};

// An earlier look's free polygon (LocalMap::free, in that look's robot frame), where that
// look stood and where this one stands (both in one frame, the mission's): what it showed
// free, for the blocked walks (close_blocked_rays).
struct PriorLook {
  const StarPolygon* free = nullptr;  // none: no earlier look (the first, or after a resume)
  core::Pose2 pose{};
  core::Pose2 here{};
};

struct LocalModelStats {
  std::size_t samples = 0;
  std::size_t pieces = 0;
  double rms = 0.0;
  std::size_t guard_candidates = 0;
  std::size_t guard_corroborated = 0;  // corroborated candidates (corroborated_points)
  std::size_t guard_points = 0;        // of them kept: those that can cut the polygon
  std::size_t guard_dropped = 0;       // unexplained readings that found the candidate list full
  bool guard_points_full = false;      // corroborated points were dropped (the list was full)
  std::size_t blocked_rays = 0;        // vertex rays closed by floor_blocked (close_blocked_rays)
  std::size_t blocked_by_prior = 0;    // ... of which the prior look's free polygon kept open
  std::size_t units = 0;
  bool model_valid = false;  // the fit was invertible (monotone in r)
};

// One look's local model. start() takes the look's readings (robot/PTU frame, §4.5.2):
// stereo features, the floor cue's obstacle bases (occupied) and its farthest free floor
// points (m = 0: the line of sight to them is free), and optionally, in step with those, the
// horizontal distance [m] at which each floor walk began (FloorCue::process); without them
// every walk counts as joined to the robot. `floor_blocked` (FloorCue::process's `blocked`):
// the bottom-row floor points of walks whose bottom row showed no floor, used only with
// close_blocked_rays (see there), as is `prior`. The spans and the prior's polygon must stay
// valid until done().
// run_unit() does one bounded unit of work; nothing allocates. Make the object static (MBs).
class LocalModelBuilder {
 public:
  LocalModelBuilder() = default;
  LocalModelBuilder(const LocalModelBuilder&) = delete;
  LocalModelBuilder& operator=(const LocalModelBuilder&) = delete;

  void start(const LocalModelParams& params, std::span<const evidence::Reading> features,
             std::span<const evidence::Reading> floor_obstacles,
             std::span<const evidence::Reading> floor_free,
             std::span<const float> floor_free_near_m = {},
             std::span<const evidence::Reading> floor_blocked = {}, PriorLook prior = {});
  // One unit of work; true when the local map is ready.
  bool run_unit();
  // Runs to the end (tests, benchmarks).
  void run() {
    while (!run_unit()) {
    }
  }
  [[nodiscard]] bool done() const { return phase_ == Phase::kDone; }

  [[nodiscard]] const LocalMap& map() const { return map_; }
  // The farthest free floor seen along each vertex ray [m] (robot frame).
  [[nodiscard]] const StarPolygon& seen_free() const { return seen_free_; }
  // The nearest evidence of an obstacle along each vertex ray [m] (∞ where none): floor-cue
  // bases, guard points and features in the robot's height band (robot frame).
  [[nodiscard]] const StarPolygon& evidence() const { return evidence_; }
  [[nodiscard]] const OccupancyModel& model() const { return model_; }
  // The samples the fit was trained on (seam copies included), valid until the next start().
  [[nodiscard]] std::span<const OccupancySample> samples() const { return samples_.span(); }
  [[nodiscard]] const LocalModelStats& stats() const { return stats_; }
  [[nodiscard]] const LocalModelParams& params() const { return params_; }
  // §5.4.4 map points of this look (robot frame), appended: obstacle points where the free
  // polygon's boundary is backed by evidence (a floor-cue base, a guard point or a feature in
  // the robot's height band within the range error), spaced obstacle_spacing_m along it;
  // exploration points where nothing backs the boundary (the floor was not seen beyond it, or
  // only the fit draws it) or on the bounding circle, spaced exploration_spacing_m,
  // gap_point_inset_m inside the boundary. False if a list was full.
  bool map_points(const MapPointParams& params, PointList& obstacles_robot,
                  PointList& exploration_robot) const;
  // Occupancy of the fitted model at (α, h, r) (0 before a fit).
  [[nodiscard]] float occupancy(float alpha_rad, float h_m, float r_m) const;

 private:
  enum class Phase : std::uint8_t {
    kIdle,
    kSamples,
    kSeam,
    kTrain,
    kGuard,
    kGuardFeatures,
    kGuardObstacles,
    kGuardPoints,
    kExtract,
    kDone
  };

  void add_reading_samples(const evidence::Reading& reading);
  void add_free_samples(const evidence::Reading& reading);
  void build_seen_free();
  void extract();

  LocalModelParams params_{};
  Phase phase_ = Phase::kIdle;
  std::span<const evidence::Reading> features_{};
  std::span<const evidence::Reading> obstacles_{};
  std::span<const evidence::Reading> free_{};
  std::span<const float> free_near_{};
  std::span<const evidence::Reading> blocked_{};
  const StarPolygon* prior_free_ = nullptr;
  core::Pose2 prior_pose_{};  // the prior look's pose in this look's robot frame
  std::size_t cursor_ = 0;
  std::size_t guard_cursor_ = 0;  // next guard candidate to corroborate
  core::FixedVector<evidence::RaySample, kLookMaxSamples> ray_samples_;
  core::FixedVector<OccupancySample, kLookMaxSamples> samples_;
  OccupancyModel model_{};
  OccupancyTrainer trainer_{};
  AlnFreeRange<float, kLookMaxPieces> free_range_{};
  core::FixedVector<GuardPoint, kMaxGuardCandidates> candidates_;
  core::FixedVector<core::Point2, kMaxGuardPoints> guard_;
  StarPolygon obstacle_polygon_{};
  StarPolygon seen_free_{};
  StarPolygon scratch_{};
  StarPolygon evidence_{};  // nearest evidence of an obstacle along each vertex ray [m]
  std::array<bool, kMaxPolygonVertices> blocked_ray_{};  // cut to the disc by floor_blocked
  LocalMap map_{};
  LocalModelStats stats_{};
};

}  // namespace boticelli::mapping
