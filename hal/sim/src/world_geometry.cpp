// World geometry for tests and benchmarks: disc clearance, trace reading and checking, shortest
// paths (see world_geometry.h). Independent of SimWorld's clearance on purpose.
#include "hal/sim/world_geometry.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <queue>
#include <utility>

namespace boticelli::hal::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Vec {
  double x;
  double y;
};

Vec operator-(Vec a, Vec b) {
  return {a.x - b.x, a.y - b.y};
}
Vec operator+(Vec a, Vec b) {
  return {a.x + b.x, a.y + b.y};
}
Vec operator*(Vec a, double s) {
  return {a.x * s, a.y * s};
}
double dot(Vec a, Vec b) {
  return a.x * b.x + a.y * b.y;
}
double cross(Vec a, Vec b) {
  return a.x * b.y - a.y * b.x;
}
double norm(Vec a) {
  return std::sqrt(a.x * a.x + a.y * a.y);  // not hypot: slow, and nothing here overflows
}

double point_segment_distance2(Vec p, Vec a, Vec b) {
  const Vec ab = b - a;
  const double len2 = dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  const Vec d = p - (a + ab * t);
  return dot(d, d);
}

// Signed distance from a point to a convex polygon (either orientation): negative inside.
double polygon_distance(const Collider& c, Vec p) {
  const std::size_t n = c.hull_size;
  if (n == 0) return kInf;
  double area2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const core::Point2& a = c.hull[i];
    const core::Point2& b = c.hull[(i + 1) % n];
    area2 += static_cast<double>(a.x_m) * static_cast<double>(b.y_m) -
             static_cast<double>(b.x_m) * static_cast<double>(a.y_m);
  }
  const double orientation = area2 >= 0.0 ? 1.0 : -1.0;
  double boundary2 = kInf;  // squared distance to the outline
  bool inside = n >= 3 && area2 != 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec a{c.hull[i].x_m, c.hull[i].y_m};
    const Vec b{c.hull[(i + 1) % n].x_m, c.hull[(i + 1) % n].y_m};
    boundary2 = std::min(boundary2, point_segment_distance2(p, a, b));
    if (orientation * cross(b - a, p - a) < 0.0) inside = false;
  }
  const double boundary = std::sqrt(boundary2);
  return inside ? -boundary : boundary;
}

// The colliders that can touch the robot's cylinder, and its clearance among them.
class ClearanceField {
 public:
  ClearanceField(const World& world, double radius_m, double height_m) : radius_m_(radius_m) {
    for (std::size_t i = 0; i < world.collider_count; ++i) {
      const Collider& c = world.colliders[i];
      if (c.z_max_m <= kFloorClearanceM || static_cast<double>(c.z_min_m) >= height_m) continue;
      colliders_.push_back(&c);
    }
  }

  double operator()(Vec p) const {
    double best = kInf;
    for (const Collider* c : colliders_) {
      const double d =
          c->circle ? norm(p - Vec{c->centre_x_m, c->centre_y_m}) - static_cast<double>(c->radius_m)
                    : polygon_distance(*c, p);
      best = std::min(best, d);
    }
    return best - radius_m_;
  }

  // Bounding box of the relevant colliders' footprints.
  void extend_bounds(Vec& lo, Vec& hi) const {
    for (const Collider* c : colliders_) {
      if (c->circle) {
        const double r = c->radius_m;
        const double cx = c->centre_x_m;
        const double cy = c->centre_y_m;
        lo = {std::min(lo.x, cx - r), std::min(lo.y, cy - r)};
        hi = {std::max(hi.x, cx + r), std::max(hi.y, cy + r)};
      } else {
        for (std::size_t k = 0; k < c->hull_size; ++k) {
          lo = {std::min(lo.x, static_cast<double>(c->hull[k].x_m)),
                std::min(lo.y, static_cast<double>(c->hull[k].y_m))};
          hi = {std::max(hi.x, static_cast<double>(c->hull[k].x_m)),
                std::max(hi.y, static_cast<double>(c->hull[k].y_m))};
        }
      }
    }
  }

  // True when the straight segment a→b is free. Sphere tracing: the clearance is 1-Lipschitz,
  // so a step of the clearance cannot cross an obstacle; steps are at least 0.1 mm (an
  // overlap shallower than 0.05 mm can slip through) and the walk gives up as blocked after
  // 10^6 steps.
  // True when the short segment a→b with end clearances ca, cb (both >= 0) is free: bisected
  // until the 1-Lipschitz bound ca + cb >= length proves each piece free, or a midpoint
  // overlaps; pieces shorter than 0.1 mm count as free (an overlap shallower than 0.05 mm
  // can slip through).
  bool edge_free(Vec a, Vec b, double ca, double cb) const {
    struct Piece {
      Vec a, b;
      double ca, cb;
    };
    std::array<Piece, 64> stack{};
    std::size_t top = 0;
    stack[top++] = {a, b, ca, cb};
    while (top > 0) {
      const Piece piece = stack[--top];
      const double length = norm(piece.b - piece.a);
      if (piece.ca + piece.cb >= length || length < 1e-4) continue;
      const Vec m = (piece.a + piece.b) * 0.5;
      const double cm = (*this)(m);
      if (cm < 0.0) return false;
      if (top + 2 > stack.size()) return false;  // not reached: depth <= log2(L / 0.1 mm)
      stack[top++] = {piece.a, m, piece.ca, cm};
      stack[top++] = {m, piece.b, cm, piece.cb};
    }
    return true;
  }

  bool visible(Vec a, Vec b) const {
    const double length = norm(b - a);
    const Vec u = length > 0.0 ? (b - a) * (1.0 / length) : Vec{0.0, 0.0};
    double s = 0.0;
    for (int step = 0; step < 1000000; ++step) {
      const double c = (*this)(a + u * s);
      if (c < 0.0) return false;
      if (s >= length) return true;
      s = std::min(length, s + std::max(c, 1e-4));
    }
    return false;
  }

 private:
  double radius_m_;
  std::vector<const Collider*> colliders_;
};

// Splits one CSV line at commas (no quoting: the trace has none).
std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    fields.push_back(line.substr(begin, comma - begin));
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  return fields;
}

bool parse_number(const std::string& field, double& value) {
  if (field.empty()) return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(field.c_str(), &end);
  return errno == 0 && end == field.c_str() + field.size() && std::isfinite(value);
}

}  // namespace

float disc_clearance_m(const World& world, float x_m, float y_m, float radius_m, float height_m) {
  const ClearanceField field(world, radius_m, height_m);
  return static_cast<float>(field(Vec{x_m, y_m}));
}

bool read_trace(const char* path, std::vector<TraceRow>& rows, std::string& error) {
  rows.clear();
  std::ifstream in(path);
  const std::string file(path);
  if (!in) {
    error = file + ":0: cannot open (" + std::strerror(errno) + ")";
    return false;
  }
  auto fail = [&](std::size_t line, const std::string& why) {
    error = file + ":" + std::to_string(line) + ": " + why;
    rows.clear();
    return false;
  };
  static constexpr std::array<const char*, 7> kColumns = {"t_s",     "x_m",      "y_m",  "yaw_rad",
                                                          "pan_rad", "tilt_rad", "state"};
  std::string line;
  if (!std::getline(in, line)) return fail(1, "empty file, expected the header");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const std::vector<std::string> header = split_fields(line);
  for (std::size_t i = 0; i < kColumns.size(); ++i) {
    if (i >= header.size() || header[i] != kColumns[i]) {
      return fail(1, "header column " + std::to_string(i + 1) + " is '" +
                         (i < header.size() ? header[i] : std::string()) + "', expected '" +
                         kColumns[i] + "' (header t_s,x_m,y_m,yaw_rad,pan_rad,tilt_rad,state,...)");
    }
  }
  // The firmware's pose columns, wherever the header puts them (all six, or none used).
  static constexpr std::array<const char*, 6> kPoseColumns = {"odo_x_m", "odo_y_m", "odo_yaw_rad",
                                                              "est_x_m", "est_y_m", "est_yaw_rad"};
  std::array<std::size_t, 6> pose_at{};
  bool pose_columns = true;
  for (std::size_t k = 0; k < kPoseColumns.size(); ++k) {
    const auto it = std::find(header.begin(), header.end(), kPoseColumns[k]);
    pose_columns = pose_columns && it != header.end();
    if (it != header.end()) pose_at[k] = static_cast<std::size_t>(it - header.begin());
  }
  std::size_t number = 1;
  bool blank_seen = false;
  std::size_t blank_line = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) {
      if (!blank_seen) blank_line = number;
      blank_seen = true;
      continue;
    }
    if (blank_seen) return fail(blank_line, "blank line before the end of the trace");
    const std::vector<std::string> f = split_fields(line);
    if (f.size() != header.size()) {
      return fail(number, std::to_string(f.size()) + " fields, the header has " +
                              std::to_string(header.size()));
    }
    TraceRow row{};
    double* values[6] = {&row.t_s, &row.x_m, &row.y_m, &row.yaw_rad, &row.pan_rad, &row.tilt_rad};
    for (std::size_t i = 0; i < 6; ++i) {
      if (!parse_number(f[i], *values[i])) {
        return fail(number, std::string(kColumns[i]) + " '" + f[i] + "' is not a finite number");
      }
    }
    row.has_pose_columns = pose_columns;
    for (std::size_t k = 0; pose_columns && k < kPoseColumns.size(); ++k) {
      double& v = k < 3 ? row.odo[k] : row.est[k - 3];
      if (!parse_number(f[pose_at[k]], v)) {
        return fail(number, std::string(kPoseColumns[k]) + " '" + f[pose_at[k]] +
                                "' is not a finite number");
      }
    }
    if (f[6].empty()) return fail(number, "empty state");
    if (f[6].size() >= sizeof row.state) {
      return fail(number, "state '" + f[6] + "' longer than " +
                              std::to_string(sizeof row.state - 1) + " characters");
    }
    std::memcpy(row.state, f[6].c_str(), f[6].size() + 1);
    if (!rows.empty() && row.t_s < rows.back().t_s) {
      return fail(number, "t_s " + f[0] + " goes back in time (previous row " +
                              std::to_string(rows.back().t_s) + ")");
    }
    rows.push_back(row);
  }
  if (in.bad()) return fail(number, "read error");
  if (rows.empty()) return fail(2, "no rows after the header");
  return true;
}

std::size_t count_reversals(const std::vector<TraceRow>& rows, double stride_m,
                            double min_turn_rad) {
  if (rows.empty()) return 0;
  struct Mark {
    double x, y;
  };
  std::vector<Mark> marks = {{rows.front().x_m, rows.front().y_m}};
  for (const TraceRow& r : rows) {
    if (std::hypot(r.x_m - marks.back().x, r.y_m - marks.back().y) >= stride_m) {
      marks.push_back({r.x_m, r.y_m});
    }
  }
  const double cos_limit = std::cos(min_turn_rad);
  std::size_t count = 0;
  for (std::size_t i = 2; i < marks.size(); ++i) {
    const double ax = marks[i - 1].x - marks[i - 2].x, ay = marks[i - 1].y - marks[i - 2].y;
    const double bx = marks[i].x - marks[i - 1].x, by = marks[i].y - marks[i - 1].y;
    count += (ax * bx + ay * by) / (std::hypot(ax, ay) * std::hypot(bx, by)) < cos_limit ? 1U : 0U;
  }
  return count;
}

TraceCheck check_trace(const World& world, const std::vector<TraceRow>& rows, float radius_m,
                       float height_m) {
  const ClearanceField field(world, radius_m, height_m);
  TraceCheck check;
  check.rows = rows.size();
  check.min_clearance_m = kInf;
  if (rows.empty()) return check;
  bool contact = false;
  auto visit = [&](double c) {
    check.min_clearance_m = std::min(check.min_clearance_m, c);
    if (!contact && c < kTraceContactM) {
      contact = true;
      ++check.collisions;
    } else if (contact && c > kTraceReleaseM) {
      contact = false;
    }
  };
  Vec previous{rows[0].x_m, rows[0].y_m};
  double c = field(previous);
  visit(c);
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const Vec next{rows[i].x_m, rows[i].y_m};
    const double length = norm(next - previous);
    check.max_gap_s = std::max(check.max_gap_s, rows[i].t_s - rows[i - 1].t_s);
    check.path_length_m += length;
    // Sub-samples at most 1 cm apart, and no farther apart than the clearance (at least
    // 0.5 mm): a 1-Lipschitz function then cannot dip far between samples.
    double s = 0.0;
    while (true) {
      s = std::min(length, s + std::clamp(std::fabs(c), 5e-4, 1e-2));
      const Vec p = length > 0.0 ? previous + (next - previous) * (s / length) : next;
      c = field(p);
      visit(c);
      if (s >= length) break;
    }
    previous = next;
  }
  return check;
}

double shortest_path_m(const World& world, core::Point2 start, core::Point2 goal,
                       float goal_radius_m, float robot_radius_m, float height_m) {
  const ClearanceField field(world, robot_radius_m, height_m);
  const Vec s{start.x_m, start.y_m};
  const Vec g{goal.x_m, goal.y_m};
  const double goal_r = goal_radius_m;
  if (field(s) < 0.0) return kInf;
  if (norm(s - g) <= goal_r) return 0.0;

  // Grid of nodes s + (i, j) h over the obstacles, the start and the goal, padded.
  constexpr double kCellM = 0.025;
  constexpr double kPadM = 0.5;
  Vec lo{std::min(s.x, g.x), std::min(s.y, g.y)};
  Vec hi{std::max(s.x, g.x), std::max(s.y, g.y)};
  field.extend_bounds(lo, hi);
  const auto i0 = static_cast<long>(std::floor((lo.x - kPadM - s.x) / kCellM));
  const auto j0 = static_cast<long>(std::floor((lo.y - kPadM - s.y) / kCellM));
  const auto i1 = static_cast<long>(std::ceil((hi.x + kPadM - s.x) / kCellM));
  const auto j1 = static_cast<long>(std::ceil((hi.y + kPadM - s.y) / kCellM));
  const long nx = i1 - i0 + 1;
  const long ny = j1 - j0 + 1;
  if (nx <= 0 || ny <= 0 || nx * ny > 40000000L) return kInf;  // beyond 1000 m worlds' sense
  auto node_point = [&](long k) {
    const long column = k % nx;  // node k of the nx-by-ny grid, row by row
    const long row = k / nx;
    return Vec{s.x + static_cast<double>(i0 + column) * kCellM,
               s.y + static_cast<double>(j0 + row) * kCellM};
  };
  const auto count = static_cast<std::size_t>(nx * ny);
  std::vector<float> clearance(count);
  for (std::size_t k = 0; k < count; ++k) {
    clearance[k] = static_cast<float>(field(node_point(static_cast<long>(k))));
  }

  // Dijkstra with 16-neighbour moves. An edge of length L between nodes of clearance ca, cb is
  // free when ca + cb >= L (every point is within L/2 of an end: the clearance is
  // 1-Lipschitz); failing that (near a wall) it is bisected with the same bound. So no edge crosses
  // a wall, however thin, and a gap only just wider than the robot is still found.
  static constexpr std::array<std::array<int, 2>, 16> kMoves = {{{1, 0},
                                                                 {-1, 0},
                                                                 {0, 1},
                                                                 {0, -1},
                                                                 {1, 1},
                                                                 {1, -1},
                                                                 {-1, 1},
                                                                 {-1, -1},
                                                                 {1, 2},
                                                                 {2, 1},
                                                                 {-1, 2},
                                                                 {-2, 1},
                                                                 {1, -2},
                                                                 {2, -1},
                                                                 {-1, -2},
                                                                 {-2, -1}}};
  std::vector<double> dist(count, kInf);
  std::vector<std::int32_t> parent(count, -1);
  using Item = std::pair<double, long>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  const long start_node = (-j0) * nx + (-i0);
  dist[static_cast<std::size_t>(start_node)] = 0.0;
  open.push({0.0, start_node});
  long reached = -1;
  while (!open.empty()) {
    const auto [d, k] = open.top();
    open.pop();
    const auto uk = static_cast<std::size_t>(k);
    if (d > dist[uk]) continue;
    const Vec p = node_point(k);
    if (norm(p - g) <= goal_r + kCellM) {  // the goal circle may hold no node: see below
      reached = k;
      break;
    }
    const long ki = k % nx;
    const long kj = k / nx;
    for (const auto& m : kMoves) {
      const long ni = ki + m[0];
      const long nj = kj + m[1];
      if (ni < 0 || nj < 0 || ni >= nx || nj >= ny) continue;
      const long n = nj * nx + ni;
      const auto un = static_cast<std::size_t>(n);
      const double ca = clearance[uk];
      const double cb = clearance[un];
      if (cb < 0.0) continue;
      const double length = kCellM * std::hypot(m[0], m[1]);
      if (ca + cb < length && !field.edge_free(p, node_point(n), ca, cb)) continue;
      if (d + length < dist[un]) {
        dist[un] = d + length;
        parent[un] = static_cast<std::int32_t>(k);
        open.push({d + length, n});
      }
    }
  }
  if (reached < 0) return kInf;

  std::vector<Vec> path;
  for (long k = reached; k >= 0; k = parent[static_cast<std::size_t>(k)])
    path.push_back(node_point(k));
  path.back() = s;  // the start node is the start itself (up to rounding)
  std::reverse(path.begin(), path.end());

  // String pulling: from each anchor go straight to the goal circle if that leg is free,
  // else to the farthest path node in a row that is visible. The last node is within one cell
  // of the goal circle; if even the short leg from it is blocked (a goal circle inside a wall)
  // that leg still counts, so the result is at most one cell off.
  double length = 0.0;
  std::size_t anchor = 0;
  while (true) {
    const Vec p = path[anchor];
    const double to_goal = norm(p - g);
    if (to_goal <= goal_r) break;
    const Vec nearest = g + (p - g) * (goal_r / to_goal);
    if (anchor + 1 == path.size() || field.visible(p, nearest)) {
      length += to_goal - goal_r;
      break;
    }
    std::size_t k = anchor + 1;
    while (k + 1 < path.size() && field.visible(p, path[k + 1])) ++k;
    length += norm(path[k] - p);
    anchor = k;
  }
  return length;
}

}  // namespace boticelli::hal::sim
