// Single-camera stereo on one frame pair (§3.4.1): features, tracks, triangulation → Readings.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"
#include "algo/image/epipolar_tracker.h"
#include "algo/image/features.h"
#include "algo/image/low_res_frame.h"
#include "algo/image/target_detector.h"
#include "algo/stereo/rig.h"

namespace boticelli::stereo {

struct StereoParams {
  image::FeatureParams features;    // cap 500, central band, min strength
  image::TrackParams tracking;      // 3 px band, E_thresh, distinctiveness
  image::TargetParams target;       // green triangle on white paper (§3.4.2)
  float match_error_max = 1500.0F;  // E_max of Eq 3.8 [grey levels²], in agreement with E_thresh
  // n_max of Eq 3.8 on the normalised error, in agreement with the tracker's threshold; a
  // reading's evidence is the larger of the two (a strong feature's E is above E_max).
  float normalized_error_max = 0.3F;
  float min_range_m = 0.2F;         // nearest depth searched, from the first optical centre [m]
  bool fast_triangulation = false;  // Eq 3.4 instead of the exact Eq 3.2
  // The target's range from its edges: the triangle's edges are tracked like features
  // (sub-pixel along the epipolar line) and the vertex put at their median horizontal
  // distance on its own line of sight; the vertex alone is two fitted lines' intersection,
  // whose row is several times less precise than a tracked edge's. Needs at least
  // target_min_edges tracked edge pixels within target_edge_window (else the vertex's own
  // triangulation stands).
  bool target_range_from_edges = false;
  std::size_t target_min_edges = 4;
  // Edges count only within this share of the vertex's one-pixel range error δr (Eq 3.7) of
  // its own distance: the vertex is located to a few tenths of a pixel, so an edge farther
  // off tracked something other than the triangle.
  float target_edge_window = 0.2F;
  float target_edge_min_strength = 4.0F;  // |∂Y/∂v| of an edge pixel [grey levels per px]
  // Two views of one look at different pans are a stereo pair too, with a baseline of
  // 2L·sin(Δpan/2) across (0.077 m for a look's 0.37 rad pan step, 2.7 times the tilt
  // pair's): locate_target_across triangulates their vertices if the rays pass within this
  // many pixels (at the point's range) of each other, a mismatch between the two rows the
  // vertex was found at.
  float target_across_max_gap_px = 1.5F;
  // Self-calibration from the floor (RangeCheck::inverse_bias): after each look whose check
  // has at least self_calibration_min_pairs pairs, the look's median inverse-range bias is
  // added to the one in use (set_inverse_range_bias), which the tilt pairs' points and target
  // fixes then have removed (remove_inverse_range_bias); |b| is held to
  // self_calibration_max_bias_per_m. Off: the ranges as the configured rig gives them.
  bool self_calibration = true;
  std::size_t self_calibration_min_pairs = 30;
  float self_calibration_max_bias_per_m = 0.5F;  // [1/m]: 1/r̂ off by this at most
  // A bias below this is the stereo's own (a calibrated rig's looks give ±0.01 m⁻¹, the
  // check's ratio within 1 ± 0.02) and is not removed: 0.025 m⁻¹ is a focal length about
  // 0.5 % off on the 0.21 m lever. The far ranges that matter in a long room are where a
  // small inverse bias moves points most (a calibrated rig corrected by −0.0095 m⁻¹ lost the
  // corridor at seed 1).
  float self_calibration_min_bias_per_m = 0.025F;  // [1/m]
  // A point the bias puts beyond this is dropped (its parallax is the bias's) [m].
  float self_calibration_max_range_m = 20.0F;
};

// Where the PTU was for the two frames [rad]: same pan; the second frame after tilting
// down by Φ (second_tilt_rad = first_tilt_rad − Φ for the thesis's rig).
struct PairPose {
  float pan_rad = 0.0F;
  float first_tilt_rad = 0.0F;
  float second_tilt_rad = 0.0F;
};

// One tracked and triangulated feature, with what went into its reading.
struct StereoPoint {
  Eigen::Vector2f first_px = Eigen::Vector2f::Zero();     // feature, low-resolution pixels
  Eigen::Vector2f second_px = Eigen::Vector2f::Zero();    // match, sub-pixel
  float match_error = 0.0F;                               // E (Eq 3.1) [grey levels²]
  float normalized_error = -1.0F;                         // the tracker's (Track), −1 if none
  Eigen::Vector3f point_ptu_m = Eigen::Vector3f::Zero();  // PTU frame [m]
  float range_camera_m = 0.0F;                            // from the first optical centre [m]
  float range_error_m = 0.0F;                             // δr of Eq 3.7 at that range [m]
  evidence::Reading reading;                              // {α, h, r, m}
};

// The target's vertex seen in one frame: the detection and where the PTU pointed [rad].
struct TargetSighting {
  image::TargetDetection detection;
  float pan_rad = 0.0F;
  float tilt_rad = 0.0F;
};

// The target (§3.4.2) found in both frames of a pair and triangulated like a feature.
struct TargetFix {
  bool found = false;       // seen in both frames and triangulated
  float confidence = 0.0F;  // the lower of the two detections'
  std::size_t edges = 0;    // tracked edge pixels that set the range (0: the vertex's own)
  // δr of Eq 3.7 at the fix's range with its two frames' baseline: one pixel of disparity
  // [m]. What a fix's error scales with, to weigh it against others.
  float range_error_m = 0.0F;
  Eigen::Vector3f point_ptu_m = Eigen::Vector3f::Zero();  // the corner, PTU frame [m]
  evidence::Reading reading;     // {α, h, r} of the corner; m = confidence
  image::TargetDetection first;  // per-frame detections (low-res px)
  image::TargetDetection second;
};

class StereoProcessor {
 public:
  static constexpr std::size_t kMaxPoints = image::FeatureSelector::kMaxFeatures;

  explicit StereoProcessor(const RigModel& rig, const StereoParams& params = {});
  [[nodiscard]] const RigModel& rig() const { return rig_; }
  [[nodiscard]] const StereoParams& params() const { return params_; }
  // The inverse-range bias b [1/m] removed from every tilt pair's point and target fix from
  // now on (remove_inverse_range_bias; 0: none, the ranges as triangulated).
  void set_inverse_range_bias(float bias_per_m) { inverse_range_bias_ = bias_per_m; }
  [[nodiscard]] float inverse_range_bias() const { return inverse_range_bias_; }

  // Averages the two YUYV frames (full resolution, as the rig's camera) by the rig's
  // downsample factor into first_frame()/second_frame(), then process()es them.
  std::size_t process_yuyv(const std::uint8_t* first_yuyv, const std::uint8_t* second_yuyv,
                           std::uint32_t stride_bytes, const PairPose& pose,
                           core::FixedVectorBase<evidence::Reading>& readings);

  // One frame pair at the rig's low resolution → readings APPENDED to `readings` (a look
  // around collects 15 pairs into one buffer); returns how many were appended. Also
  // fills features() and points(). Nothing is allocated.
  std::size_t process(const image::LowResFrame& first, const image::LowResFrame& second,
                      const PairPose& pose, core::FixedVectorBase<evidence::Reading>& readings);

  // Triangulates one correspondence (low-resolution pixels) for the given poses into the
  // PTU frame, with the configured method; used for features and for the target.
  bool triangulate(const CameraPose& first, const CameraPose& second,
                   const Eigen::Vector2f& first_px, const Eigen::Vector2f& second_px,
                   Eigen::Vector3f& point_ptu_m) const;

  // The epipolar segment (App. A) searched for a first-frame pixel: from the image of
  // the ray's point at infinity to that of its point at min_range_m.
  bool epipolar_segment(const CameraPose& first, const CameraPose& second,
                        const Eigen::Vector2f& first_px, image::EpipolarSegment& segment) const;

  // Looks for the target in both frames (low resolution, as for process()) and
  // triangulates its corner with the same routine as the features (§3.4.2).
  TargetFix locate_target(const image::LowResFrame& first, const image::LowResFrame& second,
                          const PairPose& pose);

  // The vertex triangulated from two frames of one look (the robot still) at different pans,
  // each detection where it was found: a horizontal baseline, longer than the tilt pair's for
  // pans apart by more than the tilt step Φ. found = false if either detection is missing,
  // the baseline is no longer than the tilt pair's, the rays do not meet in front of both
  // cameras or pass farther apart than target_across_max_gap_px. first/second are the two
  // detections; edges = 0 (the vertex's own). Nothing is allocated.
  [[nodiscard]] TargetFix locate_target_across(const TargetSighting& earlier,
                                               const TargetSighting& later) const;

  [[nodiscard]] const image::LowResFrame& first_frame() const { return first_; }
  [[nodiscard]] const image::LowResFrame& second_frame() const { return second_; }
  [[nodiscard]] const core::FixedVector<image::Feature, kMaxPoints>& features() const {
    return features_;
  }
  [[nodiscard]] const core::FixedVector<StereoPoint, kMaxPoints>& points() const { return points_; }

 private:
  void refine_target_range(const image::LowResFrame& first, const image::LowResFrame& second,
                           const CameraPose& pose1, const CameraPose& pose2, TargetFix& fix);

  RigModel rig_;
  StereoParams params_;
  image::FeatureSelector selector_;
  image::TargetDetector target_detector_;
  image::LowResFrame first_;
  image::LowResFrame second_;
  core::FixedVector<image::Feature, kMaxPoints> features_;
  core::FixedVector<StereoPoint, kMaxPoints> points_;
  std::array<float, 512> edge_rho_{};  // the target's edge distances [m]
  float inverse_range_bias_ = 0.0F;    // [1/m]
};

}  // namespace boticelli::stereo
