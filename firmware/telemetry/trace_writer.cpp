// TraceWriter: CSV rows through a static buffer, renamed into place at close (see trace_writer.h).
#include "firmware/telemetry/trace_writer.h"

#include <cerrno>
#include <cstring>
#include <unistd.h>

namespace boticelli::firmware::mission {

bool TraceWriter::open(const char* path, char* error, std::size_t error_size) {
  close();
  const int n = std::snprintf(path_, sizeof path_, "%s", path);
  if (n <= 0 || static_cast<std::size_t>(n) >= sizeof path_) {
    std::snprintf(error, error_size, "trace file name too long: %s", path);
    return false;
  }
  std::snprintf(part_, sizeof part_, "%s.part", path_);
  file_ = std::fopen(part_, "w");
  if (file_ == nullptr) {
    std::snprintf(error, error_size, "cannot write trace %s: %s", part_, std::strerror(errno));
    return false;
  }
  std::setvbuf(file_, buffer_, _IOFBF, sizeof buffer_);
  rows_ = 0;
  failed_ = std::fputs(
                "t_s,x_m,y_m,yaw_rad,pan_rad,tilt_rad,state,odo_x_m,odo_y_m,odo_yaw_rad,est_x_m,"
                "est_y_m,est_yaw_rad\n",
                file_) < 0;
  return true;
}

void TraceWriter::row(double t_s, const core::Pose2& pose, float pan_rad, float tilt_rad,
                      const char* state, const core::Pose2& odometry, const core::Pose2& estimate) {
  if (file_ == nullptr) return;
  if (std::fprintf(file_, "%.3f,%.4f,%.4f,%.4f,%.4f,%.4f,%s,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", t_s,
                   static_cast<double>(pose.x_m), static_cast<double>(pose.y_m),
                   static_cast<double>(pose.yaw_rad), static_cast<double>(pan_rad),
                   static_cast<double>(tilt_rad), state, static_cast<double>(odometry.x_m),
                   static_cast<double>(odometry.y_m), static_cast<double>(odometry.yaw_rad),
                   static_cast<double>(estimate.x_m), static_cast<double>(estimate.y_m),
                   static_cast<double>(estimate.yaw_rad)) < 0) {
    failed_ = true;
  }
  ++rows_;
}

bool TraceWriter::close(char* error, std::size_t error_size) {
  if (file_ == nullptr) return true;
  bool ok = !failed_ && std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
  ok = std::fclose(file_) == 0 && ok;
  file_ = nullptr;
  if (ok && std::rename(part_, path_) != 0) ok = false;
  if (!ok && error != nullptr) {
    std::snprintf(error, error_size, "trace %s not completed: %s", path_, std::strerror(errno));
  }
  return ok;
}

}  // namespace boticelli::firmware::mission
