// Floor-appearance cue: obstacle bases and seen-free floor from one frame and the ground plane.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"
#include "algo/image/low_res_frame.h"
#include "algo/stereo/rig.h"

namespace boticelli::stereo {

// Appearance-based obstacle detection (Ulrich & Nourbakhsh 2000; Horswill's Polly): what
// looks like the floor close in front of the robot is floor; walking up an image column
// from the bottom, the floor appearance stops at the base of the first obstacle, and the
// floor plane (h = −ptu_height) says how far away that base is. Stereo (§3.4) sees only
// strong vertical intensity changes; this cue sees plain boxes and featureless walls, and
// says which floor was actually seen free (unknown is not free).
//
// Appearance: each pixel's (Y, Cb, Cr) after undoing the camera's radial vignetting,
// compared per channel with the floor model's median; a pixel looks like floor when every
// channel is within the channel's tolerance max(spread_factor · σ, min tolerance), σ the
// robust spread (1.4826 · median absolute deviation) of the reference pixels.
struct FloorCueParams {
  float max_range_m = 3.0F;  // the floor is looked at up to this horizontal distance ρ [m]
  // Reference region: pixels of the bottom rows whose rays meet the floor at a horizontal
  // distance ρ from the PTU centre in [reference_min_m, reference_max_m] [m].
  float reference_min_m = 0.4F;
  float reference_max_m = 1.0F;
  std::uint32_t reference_rows_max = 40;     // bottom rows searched for the region [px]
  std::uint32_t reference_min_pixels = 150;  // fewer: nothing is learned
  float vignetting = 0.25F;                  // camera's brightness loss at the image corners [0, 1)
  float spread_factor = 4.0F;                // tolerance in robust standard deviations
  float min_tolerance_luma = 10.0F;          // smallest luma tolerance [grey levels]
  float min_tolerance_chroma = 5.0F;         // smallest chroma tolerance [chroma levels]
  // A region whose spread asks for more than these is not one surface (kNotUniform): half
  // wall, half floor, its median between the two and 4σ wide enough to call both floor. A
  // plain floor's own spread is the sensor noise (σ ≈ 2 grey levels, so the minimum applies).
  float max_tolerance_luma = 30.0F;    // [grey levels]
  float max_tolerance_chroma = 15.0F;  // [chroma levels]
  // Learning accepts a region only if at least this fraction of its pixels look like floor,
  // both to the region's own model and to the model already known (if any).
  float consistency_min = 0.9F;
  float learn_rate = 0.5F;  // weight of a fresh region when updating a model, (0, 1]
  // The first model needs two regions that agree, seen from pans at least this far apart
  // [rad]: a plain box or wall filling one view's region (the robot beside it) is uniform and
  // would be learned as the floor, and every later region of the real floor would then be
  // refused as inconsistent. The floor is what views in different directions share. 0 trusts
  // the first region (the reference area of Ulrich & Nourbakhsh, assumed free).
  float confirm_separation_rad = 1.0F;
  std::uint32_t column_step = 2;   // every column_step-th column is walked [px]
  std::uint32_t boundary_run = 3;  // k: non-floor pixels in a row that end the floor [px]
  // Obstacle readings at the base's ρ, at these heights above the floor [m] (the robot must
  // not assume a plain object is lower than itself).
  std::array<float, 4> obstacle_heights_m{0.05F, 0.2F, 0.4F, 0.0F};
  std::uint32_t obstacle_height_count = 3;
  // Evidence m of a boundary from its contrast c (how many tolerances the k pixels above
  // the base are from the floor model, median): evidence_weak at c = 1, rising linearly to
  // evidence_clear at c ≥ clear_contrast.
  float evidence_weak = 0.4F;
  float evidence_clear = 0.9F;
  float clear_contrast = 2.5F;
  // Textured floors (a rug, wood, tile): a region too busy for one colour (kNotUniform) is
  // learned as a textured floor when its colour changes often enough: at least
  // texture_min_edges of the pairs of neighbouring reference pixels differ by more than the
  // minimum tolerances (a region half wall, half floor changes once per row), and its near
  // and far halves hold each other's colours (a textured wall across the far part does not). Its
  // model is the region's colour histogram (Ulrich & Nourbakhsh 2000): a pixel looks like this
  // floor when the pixels of its bin and the bins next to it hold at least texture_min_share of the
  // region. A plain object can wear one of the floor's colours, but not its texture: a walk on a
  // textured floor ends where one colour runs on for longer than the floor's patches do
  // (texture_run_factor times the 95th percentile, by length, of the region's runs along its rows,
  // in metres of floor, within [texture_run_min_m, texture_run_max_m]). false: a busy region is
  // never learned (the plain-floor cue alone).
  bool textured = true;
  // A plain stretch on a textured floor always ends the walk's free floor (unknown is not
  // free); with texture_obstacles it is also an obstacle base (evidence_clear). Off by
  // default: a rug's largest patches are plain stretches too, and would be phantom bases
  // where nothing stands; a plain thing on the floor shows its edges to the stereo, and the
  // floor beyond it is not seen free.
  bool texture_obstacles = false;
  float texture_min_edges = 0.02F;
  float texture_min_share = 0.02F;
  float texture_run_factor = 3.0F;
  float texture_run_min_m = 0.4F;
  float texture_run_max_m = 0.6F;
};

// The colour histogram of a textured floor: Y in 16 bins of 16 levels, Cb and Cr (offsets
// from 128, clamped to ±32) in 8 bins of 8.
inline constexpr std::size_t kFloorLumaBins = 16;
inline constexpr std::size_t kFloorChromaBins = 8;
inline constexpr std::size_t kFloorBins = kFloorLumaBins * kFloorChromaBins * kFloorChromaBins;

// What the floor looks like: per channel (0 Y, 1 Cb, 2 Cr; vignetting undone) [grey levels].
struct FloorModel {
  bool valid = false;
  std::array<float, 3> median{};     // Y in 0..255, Cb and Cr as offsets from 128
  std::array<float, 3> tolerance{};  // the floor test's half width per channel
  // A textured floor (FloorCueParams::textured): the colour test is the histogram's, and
  // tolerance says what a change of colour along a walk is: the chroma minimum, and half the
  // region's typical luma step between patches (at least the luma minimum), so that two
  // faces of one plain thing, shaded apart, are not taken for the floor's patches.
  bool textured = false;
  std::array<float, kFloorBins> mass{};   // share of the region's pixels in each bin
  std::array<float, kFloorBins> share{};  // the same summed over each bin and its neighbours
  float max_run_m = 0.0F;  // longest run of one colour the floor shows, in metres of floor
};

enum class FloorLearn : std::uint8_t {
  kLearned,       // first model, from a self-consistent region
  kUpdated,       // region agreed with the known model; model blended towards it
  kNoRegion,      // the geometry gives too few reference pixels at this tilt
  kNotUniform,    // the region does not agree with itself (something else in it)
  kInconsistent,  // the region does not look like the known floor (obstacle in front)
  kPending,       // no model yet: the region waits for one from another direction to agree
};

// One walk of the last process() call: up the image of the vertical plane through the
// optical centre and one bottom-row pixel (the floor along it is one line of sight).
struct FloorColumn {
  enum class End : std::uint8_t {
    kBoundary,         // the floor stopped at an obstacle's base
    kMaxRange,         // the floor reached max_range_m (or the horizon)
    kImageEdge,        // the walk left the image (top or side) still closer than max_range_m
    kBlockedAtBottom,  // the bottom row already does not look like floor: nothing said
  };
  std::uint32_t u_px = 0;  // the walk's bottom-row pixel column [px]
  End end = End::kBlockedAtBottom;
  float azimuth_rad = 0.0F;  // direction of the walk's vertical plane, PTU frame, [0, 2π)
  float near_rho_m = 0.0F;   // horizontal distance (PTU centre) of its bottom-row floor point [m]
  float base_rho_m = 0.0F;   // kBoundary: horizontal distance of the obstacle base [m]
  float free_rho_m = 0.0F;   // horizontal distance of the free reading, 0 if none [m]
  float evidence = 0.0F;     // kBoundary: m of the obstacle readings
};

struct FloorCueResult {
  std::size_t obstacle_readings = 0;  // appended to `obstacles`
  std::size_t free_readings = 0;      // appended to `free`
  std::size_t blocked_readings = 0;   // appended to `blocked`
  std::size_t columns = 0;            // columns walked
  std::size_t boundaries = 0;         // columns ending at an obstacle base
  bool truncated = false;             // an output was full: some readings were dropped
  bool model_valid = false;           // false: nothing was done (no floor model yet)
  std::size_t deferred_walked = 0;    // kept frames walked first (the model just came)
  bool deferred = false;              // no model yet: the frame was kept for later
  bool deferred_dropped = false;      // no model yet and no room (or too large): frame lost
};

class FloorCue {
 public:
  static constexpr std::size_t kMaxColumns = image::LowResFrame::kMaxWidth;

  explicit FloorCue(const RigModel& rig, const FloorCueParams& params = {});
  [[nodiscard]] const FloorCueParams& params() const { return params_; }
  [[nodiscard]] const FloorModel& model() const { return model_; }
  void reset() {
    model_ = FloorModel{};
    pending_.fill(FloorModel{});
    pending_next_ = 0;
    deferred_count_ = deferred_next_ = 0;
  }
  // Another look begins (the robot may have moved): kept frames belong to the last pose, drop them.
  void begin_look() { deferred_count_ = deferred_next_ = 0; }
  // Frames kept while the first model waits for a second direction (walked once it is
  // confirmed, one per process() call besides the current frame, so the views before it lose
  // nothing and no call walks more than two frames): slots of the rig's low-resolution size,
  // luma rounded to whole levels (about 58 KB each). A look's lowest row walks two frames a
  // view, so 24 slots keep the first 12 views of 15 (a cluttered place's first model can wait
  // that long).
  static constexpr std::size_t kDeferredSlots = 24;
  static constexpr std::size_t kDeferredPixels = std::size_t{160} * 120;

  // Learns (or, if one is known, updates) the floor model from the frame's reference
  // region for the PTU at pan/tilt [rad]. Nothing changes unless kLearned or kUpdated.
  FloorLearn learn(const image::LowResFrame& frame, float pan_rad, float tilt_rad);

  // Without a model yet, keeps the frame (up to kDeferredSlots) and returns; with one, walks
  // the oldest kept frame first, if any (its readings are appended as well), then this one.
  // Walks one frame (the rig's low resolution) seen at pan/tilt [rad] with the current
  // model: every column_step-th pixel of the highest row that sees the floor within max
  // range gives one walk up its vertical plane from where that plane enters the image.
  // A sample is floor only if both pixels either side of the walk look like floor. APPENDS to
  // `obstacles` readings at the base of each boundary (one per configured height, m from the
  // contrast) and to `free` one reading per column with m = 0 at the farthest floor point connected
  // to the bottom of the image (the line of sight to it is free). Never writes past either
  // capacity. Nothing is allocated.
  // `free_near_m`, if given, gets in step with `free` the horizontal distance [m] of each
  // walk's near end (where it entered the image): the walk saw the floor from there to its
  // free reading. A walk that starts beyond an obstacle (a high view looking over a low box,
  // or over a wall the floor model took for floor) says nothing about the floor before it;
  // the Think stage joins walks to the robot only where they meet (LocalModelBuilder).
  // `blocked`, if given, gets one reading (m = evidence_weak) at the bottom-row floor point of
  // each walk whose bottom row already does not look like floor (kBlockedAtBottom):
  // something stands on the floor nearer than that point, or on it.
  FloorCueResult process(const image::LowResFrame& frame, float pan_rad, float tilt_rad,
                         core::FixedVectorBase<evidence::Reading>& obstacles,
                         core::FixedVectorBase<evidence::Reading>& free,
                         core::FixedVectorBase<float>* free_near_m = nullptr,
                         core::FixedVectorBase<evidence::Reading>* blocked = nullptr);

  // Columns of the last process() call.
  [[nodiscard]] std::size_t column_count() const { return column_count_; }
  [[nodiscard]] const FloorColumn& column(std::size_t i) const { return columns_[i]; }

  // Is the pixel floor to the current model? `contrast` gets the largest channel distance
  // in tolerances (≤ 1 for floor). False without a model.
  bool looks_like_floor(const image::LowResFrame& frame, std::uint32_t u, std::uint32_t v,
                        float& contrast) const;

  // Horizontal distances from the PTU centre [m] at which the image's centre column meets
  // the floor at tilt [rad]: bottom row (near) and top row (far, +inf if the top row is at
  // or above the horizon). False if no row of the centre column sees the floor.
  bool floor_coverage(float tilt_rad, float& near_m, float& far_m) const;

 private:
  // The line of sight from the optical centre at azimuth/elevation [rad] (PTU frame) meets
  // the floor: the floor point (PTU frame) and its ρ [m].
  bool sight_floor_point(const CameraPose& pose, float azimuth_rad, float elevation_rad,
                         Eigen::Vector3f& point, float& rho_m) const;
  // Ray of pixel (u, v) meets the floor: the floor point (PTU frame) and its ρ [m].
  bool floor_point(const CameraPose& pose, float u, float v, Eigen::Vector3f& point,
                   float& rho_m) const;
  FloorCueResult walk(const image::LowResFrame& frame, float pan_rad, float tilt_rad,
                      core::FixedVectorBase<evidence::Reading>& obstacles,
                      core::FixedVectorBase<evidence::Reading>& free,
                      core::FixedVectorBase<float>* free_near_m,
                      core::FixedVectorBase<evidence::Reading>* blocked);
  void pixel_values(const image::LowResFrame& frame, std::uint32_t u, std::uint32_t v,
                    std::array<float, 3>& values) const;
  // How far `values` lie from the model, in tolerances (≤ 1 is floor); for a textured model,
  // texture_min_share over the share of the values' bin (infinite for an empty bin).
  float contrast_to(const FloorModel& model, const std::array<float, 3>& values) const;
  // Learns a textured candidate from the first `count` reference_ pixels; false if the
  // region is not textured (too few colour changes along its rows) or not one texture (its
  // near and far halves do not hold each other's colours: a wall across its far part).
  bool textured_candidate(std::size_t count, FloorModel& candidate);

  RigModel rig_;
  FloorCueParams params_;
  FloorModel model_;
  // Regions waiting for one from another direction to agree (a cluttered place can show
  // several unlike ones before two agree), with their pans; the oldest gives way.
  static constexpr std::size_t kPendingSlots = 4;
  std::array<FloorModel, kPendingSlots> pending_{};
  std::array<float, kPendingSlots> pending_pan_rad_{};
  std::size_t pending_next_ = 0;
  struct DeferredFrame {
    std::uint32_t width = 0;
    std::uint32_t height = 0;
    float pan_rad = 0.0F;
    float tilt_rad = 0.0F;
    std::array<std::uint8_t, kDeferredPixels> luma{};  // rounded: the floor test allows ≥ 10 levels
    std::array<std::uint8_t, kDeferredPixels> chroma_u{};
    std::array<std::uint8_t, kDeferredPixels> chroma_v{};
  };
  std::array<DeferredFrame, kDeferredSlots> deferred_{};
  std::size_t deferred_count_ = 0;
  std::size_t deferred_next_ = 0;  // the next kept frame to walk
  image::LowResFrame scratch_{};   // a kept frame, unpacked for its walk
  std::array<FloorColumn, kMaxColumns> columns_{};
  std::size_t column_count_ = 0;
  // Reference pixels of the region being learned (compensated values), for the robust stats.
  static constexpr std::size_t kMaxReference = std::size_t{kMaxColumns} * 64;
  std::array<std::array<std::uint8_t, 3>, kMaxReference> reference_{};
  // Floor distance from each reference pixel to the one before it in the list when that is
  // its left neighbour on the row [m], else negative: the texture along the rows.
  std::array<float, kMaxReference> reference_step_m_{};
  std::array<float, kMaxReference> reference_rho_m_{};  // each one's ρ [m]
  // Scratch of textured_candidate: the region's near and far halves' histograms.
  std::array<float, kFloorBins> near_mass_{};
  std::array<float, kFloorBins> far_mass_{};
  std::array<float, kFloorBins> half_mass_{};
  std::array<float, kFloorBins> half_share_{};
};

}  // namespace boticelli::stereo
