// TraceWriter: the --trace CSV (docs/mission.md, "The trace") — pose, PTU angles and state, written
// without allocation and renamed into place when closed.
#pragma once

#include <cstddef>
#include <cstdio>

#include "algo/core/geometry.h"

namespace boticelli::firmware::mission {

// Header `t_s,x_m,y_m,yaw_rad,pan_rad,tilt_rad,state,odo_x_m,odo_y_m,odo_yaw_rad,est_x_m,
// est_y_m,est_yaw_rad`. On the sim board x, y, yaw are the simulator's true pose (world frame;
// on hardware the firmware's estimate), the odo_ columns the wheel odometry alone and the est_
// columns the firmware's own pose (registered looks, odometry between), both in the mission
// frame. Rows go to FILE.part through a static stdio buffer (written
// out whenever it fills); close() flushes, fsyncs and renames FILE.part to FILE, so a
// finished trace is never half written and a crashed run leaves its rows in FILE.part.
class TraceWriter {
 public:
  TraceWriter() = default;
  ~TraceWriter() { close(); }
  TraceWriter(const TraceWriter&) = delete;
  TraceWriter& operator=(const TraceWriter&) = delete;

  // Opens FILE.part (allocates inside stdio: call at init); false with a reason.
  bool open(const char* path, char* error, std::size_t error_size);
  void row(double t_s, const core::Pose2& pose, float pan_rad, float tilt_rad, const char* state,
           const core::Pose2& odometry, const core::Pose2& estimate);
  // Flushes and renames into place; false with a reason if a write failed.
  bool close(char* error = nullptr, std::size_t error_size = 0);
  [[nodiscard]] bool is_open() const { return file_ != nullptr; }
  [[nodiscard]] std::size_t rows() const { return rows_; }

 private:
  std::FILE* file_ = nullptr;
  char path_[512] = {};
  char part_[520] = {};
  char buffer_[1 << 16] = {};
  std::size_t rows_ = 0;
  bool failed_ = false;
};

}  // namespace boticelli::firmware::mission
