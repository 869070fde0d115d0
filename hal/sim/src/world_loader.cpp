// World loader: reads the SDF 1.6 subset of docs/worlds.md with tinyxml2, validating every value.
#include <tinyxml2.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "hal/sim/world.h"

namespace boticelli::hal::sim {

RigidTransform transform_from_pose(const float xyz_rpy[6]) {
  const float cr = std::cos(xyz_rpy[3]), sr = std::sin(xyz_rpy[3]);
  const float cp = std::cos(xyz_rpy[4]), sp = std::sin(xyz_rpy[4]);
  const float cy = std::cos(xyz_rpy[5]), sy = std::sin(xyz_rpy[5]);
  Eigen::Matrix3f rx;
  rx << 1.0F, 0.0F, 0.0F, 0.0F, cr, -sr, 0.0F, sr, cr;
  Eigen::Matrix3f ry;
  ry << cp, 0.0F, sp, 0.0F, 1.0F, 0.0F, -sp, 0.0F, cp;
  Eigen::Matrix3f rz;
  rz << cy, -sy, 0.0F, sy, cy, 0.0F, 0.0F, 0.0F, 1.0F;
  RigidTransform t;
  t.rotation = rz * ry * rx;
  t.translation_m = Eigen::Vector3f(xyz_rpy[0], xyz_rpy[1], xyz_rpy[2]);
  return t;
}

TargetFace target_face_frame(const Surface& s) {
  const int axis = s.target_face / 2;
  const float sign = (s.target_face % 2 == 0) ? 1.0F : -1.0F;
  Eigen::Vector3f n_local = Eigen::Vector3f::Zero();
  n_local[axis] = sign;
  Eigen::Vector3f centre_local = n_local * s.half_size_m[axis];
  // "Up" on the face: the world's +z projected into the face; on ±z faces the box's +y.
  Eigen::Vector3f up_local = s.world_from_local.rotation.transpose() * Eigen::Vector3f::UnitZ();
  up_local -= n_local * up_local.dot(n_local);
  if (up_local.norm() < 0.1F) {
    up_local = Eigen::Vector3f::UnitY();
    up_local -= n_local * up_local.dot(n_local);
  }
  up_local.normalize();
  const Eigen::Vector3f right_local = up_local.cross(n_local);
  const Eigen::Matrix3f& r = s.world_from_local.rotation;
  return {s.world_from_local.apply(centre_local), r * n_local, r * right_local, r * up_local};
}

namespace {

using tinyxml2::XMLElement;

constexpr float kMaxCoordinate_m = 1000.0F;
constexpr float kMaxSize_m = 1000.0F;

// Collects the first error as "FILE:LINE: message".
class Errors {
 public:
  Errors(const char* file, char* buffer, std::size_t size)
      : file_(file), buffer_(buffer), size_(size) {}
  bool fail(int line, const char* fmt, ...) __attribute__((format(printf, 3, 4))) {
    if (failed_) return false;
    failed_ = true;
    if (size_ == 0) return false;
    // Problems with the file as a whole (it cannot be read) have no line.
    const int n = line > 0 ? std::snprintf(buffer_, size_, "%s:%d: ", file_, line)
                           : std::snprintf(buffer_, size_, "%s: ", file_);
    if (n >= 0 && static_cast<std::size_t>(n) < size_) {
      va_list args;
      va_start(args, fmt);
      std::vsnprintf(buffer_ + n, size_ - static_cast<std::size_t>(n), fmt, args);
      va_end(args);
    }
    return false;
  }
  bool failed() const { return failed_; }

 private:
  const char* file_;
  char* buffer_;
  std::size_t size_;
  bool failed_ = false;
};

bool is_name(const XMLElement* e, const char* name) {
  return std::strcmp(e->Name(), name) == 0;
}

// Parses exactly `count` finite numbers (or between min_count and count) from an element's text.
bool parse_numbers(const XMLElement* e, float* out, int min_count, int count, Errors& errors) {
  const char* text = e->GetText();
  if (text == nullptr) {
    return errors.fail(e->GetLineNum(), "<%s> is empty, expected %d numbers", e->Name(), count);
  }
  const char* p = text;
  int n = 0;
  while (true) {
    while (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r') ++p;
    if (*p == '\0') break;
    if (n == count) {
      return errors.fail(e->GetLineNum(), "<%s> has more than %d numbers: '%.40s'", e->Name(),
                         count, text);
    }
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(p, &end);
    const bool separated = end != nullptr && (*end == '\0' || *end == ' ' || *end == '\t' ||
                                              *end == '\n' || *end == '\r');
    if (end == p || !separated || errno == ERANGE || !std::isfinite(v) || std::fabs(v) > 1e6) {
      return errors.fail(e->GetLineNum(), "<%s>: '%.40s' is not a number", e->Name(), p);
    }
    out[n++] = static_cast<float>(v);
    p = end;
  }
  if (n < min_count) {
    return errors.fail(e->GetLineNum(), "<%s> has %d numbers, expected %d", e->Name(), n, count);
  }
  return true;
}

const XMLElement* required_child(const XMLElement* parent, const char* name, Errors& errors) {
  const XMLElement* child = parent->FirstChildElement(name);
  if (child == nullptr) {
    errors.fail(parent->GetLineNum(), "<%s> has no <%s>", parent->Name(), name);
  }
  return child;
}

bool parse_pose(const XMLElement* parent, RigidTransform& out, Errors& errors) {
  out = RigidTransform{};
  const XMLElement* pose = parent->FirstChildElement("pose");
  if (pose == nullptr) return true;
  float v[6] = {};
  if (!parse_numbers(pose, v, 6, 6, errors)) return false;
  for (int i = 0; i < 3; ++i) {
    if (std::fabs(v[i]) > kMaxCoordinate_m) {
      return errors.fail(pose->GetLineNum(), "<pose> coordinate %g is beyond %g m",
                         static_cast<double>(v[i]), static_cast<double>(kMaxCoordinate_m));
    }
  }
  out = transform_from_pose(v);
  return true;
}

bool parse_colour(const XMLElement* e, Rgb& out, Errors& errors) {
  float v[4] = {0.0F, 0.0F, 0.0F, 1.0F};
  if (!parse_numbers(e, v, 3, 4, errors)) return false;
  for (int i = 0; i < 4; ++i) {
    if (v[i] < 0.0F || v[i] > 1.0F) {
      return errors.fail(e->GetLineNum(), "<%s>: colour component %g is outside [0, 1]", e->Name(),
                         static_cast<double>(v[i]));
    }
  }
  out = {v[0], v[1], v[2]};
  return true;
}

bool parse_positive(const XMLElement* e, float* v, int count, Errors& errors) {
  if (!parse_numbers(e, v, count, count, errors)) return false;
  for (int i = 0; i < count; ++i) {
    if (!(v[i] > 0.0F) || v[i] > kMaxSize_m) {
      return errors.fail(e->GetLineNum(), "<%s>: size %g must be > 0 and <= %g m", e->Name(),
                         static_cast<double>(v[i]), static_cast<double>(kMaxSize_m));
    }
  }
  return true;
}

// Reads <geometry> into shape, half sizes and (for planes) the rotation to the plane frame.
bool parse_geometry(const XMLElement* owner, Shape& shape, Eigen::Vector3f& half,
                    RigidTransform& plane_frame, Errors& errors) {
  const XMLElement* geometry = required_child(owner, "geometry", errors);
  if (geometry == nullptr) return false;
  const XMLElement* g = geometry->FirstChildElement();
  if (g == nullptr) return errors.fail(geometry->GetLineNum(), "<geometry> has no shape");
  if (g->NextSiblingElement() != nullptr) {
    return errors.fail(g->NextSiblingElement()->GetLineNum(),
                       "<geometry> has more than one shape (<%s>)",
                       g->NextSiblingElement()->Name());
  }
  plane_frame = RigidTransform{};
  if (is_name(g, "box")) {
    const XMLElement* size = required_child(g, "size", errors);
    float v[3];
    if (size == nullptr || !parse_positive(size, v, 3, errors)) return false;
    shape = Shape::kBox;
    half = Eigen::Vector3f(v[0], v[1], v[2]) * 0.5F;
    return true;
  }
  if (is_name(g, "cylinder")) {
    const XMLElement* radius = required_child(g, "radius", errors);
    float r;
    if (radius == nullptr || !parse_positive(radius, &r, 1, errors)) return false;
    const XMLElement* length = required_child(g, "length", errors);
    float l;
    if (length == nullptr || !parse_positive(length, &l, 1, errors)) return false;
    shape = Shape::kCylinder;
    half = Eigen::Vector3f(r, r, 0.5F * l);
    return true;
  }
  if (is_name(g, "plane")) {
    const XMLElement* size = required_child(g, "size", errors);
    float v[2];
    if (size == nullptr || !parse_positive(size, v, 2, errors)) return false;
    Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
    if (const XMLElement* n = g->FirstChildElement("normal"); n != nullptr) {
      float nv[3];
      if (!parse_numbers(n, nv, 3, 3, errors)) return false;
      normal = Eigen::Vector3f(nv[0], nv[1], nv[2]);
      if (normal.norm() < 1e-6F) return errors.fail(n->GetLineNum(), "<normal> is zero");
      normal.normalize();
    }
    // Plane frame: local z along the normal, x as close to the parent's x as possible.
    Eigen::Vector3f x = Eigen::Vector3f::UnitX() - normal * normal.x();
    if (x.norm() < 0.1F) x = Eigen::Vector3f::UnitY() - normal * normal.y();
    x.normalize();
    plane_frame.rotation.col(0) = x;
    plane_frame.rotation.col(1) = normal.cross(x);
    plane_frame.rotation.col(2) = normal;
    shape = Shape::kPlane;
    half = Eigen::Vector3f(0.5F * v[0], 0.5F * v[1], 0.0F);
    return true;
  }
  return errors.fail(g->GetLineNum(),
                     "unsupported geometry <%s> (only box, cylinder and plane are drawn)",
                     g->Name());
}

std::uint32_t parse_seed(const XMLElement* e, Errors& errors) {
  const char* text = e->Attribute("seed");
  if (text == nullptr) return 1;
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (end == text || *end != '\0' || errno == ERANGE || v > 0xFFFFFFFFULL || text[0] == '-') {
    errors.fail(e->GetLineNum(), "seed '%.20s' is not an unsigned 32-bit integer", text);
    return 0;
  }
  return static_cast<std::uint32_t>(v);
}

bool parse_attribute_float(const XMLElement* e, const char* name, float& out, Errors& errors) {
  const char* text = e->Attribute(name);
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !std::isfinite(v) || std::fabs(v) > 1e6) {
    return errors.fail(e->GetLineNum(), "<%s %s='%.20s'> is not a number", e->Name(), name, text);
  }
  out = static_cast<float>(v);
  return true;
}

struct Loader {
  World& world;
  Errors& errors;
  int targets = 0;
  int target_line = 0;

  bool load_visual(const XMLElement* visual, const RigidTransform& link, const char* model) {
    if (world.surface_count == kMaxSurfaces) {
      return errors.fail(visual->GetLineNum(), "more than %zu visuals", kMaxSurfaces);
    }
    RigidTransform pose;
    if (!parse_pose(visual, pose, errors)) return false;
    Surface s;
    RigidTransform plane_frame;
    if (!parse_geometry(visual, s.shape, s.half_size_m, plane_frame, errors)) return false;
    s.world_from_local = link.then(pose).then(plane_frame);
    std::snprintf(s.model, sizeof s.model, "%s", model);
    s.line = visual->GetLineNum();
    if (const XMLElement* material = visual->FirstChildElement("material"); material != nullptr) {
      if (const XMLElement* d = material->FirstChildElement("diffuse"); d != nullptr) {
        if (!parse_colour(d, s.diffuse, errors)) return false;
      }
    }
    if (const XMLElement* p = visual->FirstChildElement("boticelli:pattern"); p != nullptr) {
      const char* kind = p->GetText() != nullptr ? p->GetText() : "";
      while (*kind == ' ' || *kind == '\n' || *kind == '\t' || *kind == '\r') ++kind;
      std::size_t len = std::strlen(kind);
      while (len > 0 && (kind[len - 1] == ' ' || kind[len - 1] == '\n' || kind[len - 1] == '\t' ||
                         kind[len - 1] == '\r')) {
        --len;
      }
      auto is = [&](const char* word) {
        return len == std::strlen(word) && std::strncmp(kind, word, len) == 0;
      };
      if (is("plain")) {
        s.pattern = Pattern::kPlain;
      } else if (is("camouflage")) {
        s.pattern = Pattern::kCamouflage;
      } else if (is("leaves")) {
        s.pattern = Pattern::kLeaves;
      } else if (is("paper")) {
        s.pattern = Pattern::kPaper;
      } else {
        return errors.fail(p->GetLineNum(),
                           "unknown pattern '%.*s' (plain, camouflage, leaves or paper)",
                           static_cast<int>(std::min<std::size_t>(len, 40)), kind);
      }
      if (p->Attribute("scale") != nullptr) {
        if (!parse_attribute_float(p, "scale", s.pattern_scale_m, errors)) return false;
        if (!(s.pattern_scale_m >= 0.005F && s.pattern_scale_m <= 10.0F)) {
          return errors.fail(p->GetLineNum(), "pattern scale %g m is outside [0.005, 10]",
                             static_cast<double>(s.pattern_scale_m));
        }
      }
      s.pattern_seed = parse_seed(p, errors);
      if (errors.failed()) return false;
    }
    if (const XMLElement* t = visual->FirstChildElement("boticelli:target"); t != nullptr) {
      if (!load_target(t, s)) return false;
    }
    world.surfaces[world.surface_count++] = s;
    return true;
  }

  bool load_target(const XMLElement* t, Surface& s) {
    if (s.shape != Shape::kBox) {
      return errors.fail(t->GetLineNum(), "<boticelli:target> must be on a box visual");
    }
    if (++targets > 1) {
      return errors.fail(t->GetLineNum(), "a second <boticelli:target> (the first is on line %d)",
                         target_line);
    }
    target_line = t->GetLineNum();
    const char* face = t->Attribute("face");
    static constexpr const char* kFaces[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
    if (face == nullptr) return errors.fail(t->GetLineNum(), "<boticelli:target> has no face");
    for (int i = 0; i < 6; ++i) {
      if (std::strcmp(face, kFaces[i]) == 0) s.target_face = i;
    }
    if (s.target_face == kNoFace) {
      return errors.fail(t->GetLineNum(), "target face '%.8s' is not one of +x -x +y -y +z -z",
                         face);
    }
    if (t->Attribute("size") == nullptr) {
      return errors.fail(t->GetLineNum(), "<boticelli:target> has no size");
    }
    if (!parse_attribute_float(t, "size", s.target_size_m, errors)) return false;
    // The triangle must fit on the face: its bounding box is size x size*sqrt(3)/2.
    const int axis = s.target_face / 2;
    const float a = 2.0F * s.half_size_m[(axis + 1) % 3];
    const float b = 2.0F * s.half_size_m[(axis + 2) % 3];
    if (!(s.target_size_m > 0.0F) || s.target_size_m > std::min(a, b)) {
      return errors.fail(t->GetLineNum(), "target size %g m must be > 0 and fit the %gx%g m face",
                         static_cast<double>(s.target_size_m), static_cast<double>(a),
                         static_cast<double>(b));
    }
    return true;
  }

  bool load_collision(const XMLElement* collision, const RigidTransform& link, const char* model) {
    RigidTransform pose;
    if (!parse_pose(collision, pose, errors)) return false;
    Shape shape;
    Eigen::Vector3f half;
    RigidTransform plane_frame;
    if (!parse_geometry(collision, shape, half, plane_frame, errors)) return false;
    if (shape == Shape::kPlane) return true;  // planes never collide
    return add_collider(shape, half, link.then(pose), model, collision->GetLineNum());
  }

  bool add_collider(Shape shape, const Eigen::Vector3f& half, const RigidTransform& t,
                    const char* model, int line) {
    if (world.collider_count == kMaxColliders) {
      return errors.fail(line, "more than %zu collision shapes", kMaxColliders);
    }
    Collider c;
    std::snprintf(c.model, sizeof c.model, "%s", model);
    c.line = line;
    const Eigen::Vector3f axis_z = t.rotation.col(2);
    if (shape == Shape::kCylinder && std::fabs(axis_z.z()) > 0.9999F) {
      // Upright cylinder: exact circle.
      c.circle = true;
      c.centre_x_m = t.translation_m.x();
      c.centre_y_m = t.translation_m.y();
      c.radius_m = half.x();
      c.z_min_m = t.translation_m.z() - half.z();
      c.z_max_m = t.translation_m.z() + half.z();
    } else {
      // Box (or tilted cylinder, by its bounding box): the convex hull of the 8 corners
      // seen from above; exact for upright boxes, conservative otherwise.
      core::Point2 pts[8];
      c.z_min_m = 1e9F;
      c.z_max_m = -1e9F;
      for (int i = 0; i < 8; ++i) {
        const Eigen::Vector3f corner((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(),
                                     (i & 4) ? half.z() : -half.z());
        const Eigen::Vector3f w = t.apply(corner);
        pts[i] = {w.x(), w.y()};
        c.z_min_m = std::min(c.z_min_m, w.z());
        c.z_max_m = std::max(c.z_max_m, w.z());
      }
      c.hull_size = convex_hull(pts, 8, c.hull);
    }
    world.colliders[world.collider_count++] = c;
    return true;
  }

  // Andrew's monotone chain; returns the counter-clockwise hull (degenerate input keeps ≥ 1).
  static std::size_t convex_hull(core::Point2* p, std::size_t n, core::Point2* out) {
    std::sort(p, p + n, [](core::Point2 a, core::Point2 b) {
      return a.x_m < b.x_m || (a.x_m == b.x_m && a.y_m < b.y_m);
    });
    core::Point2 h[2 * 8];
    std::size_t k = 0;
    auto cross = [](core::Point2 o, core::Point2 a, core::Point2 b) {
      return (a.x_m - o.x_m) * (b.y_m - o.y_m) - (a.y_m - o.y_m) * (b.x_m - o.x_m);
    };
    for (std::size_t i = 0; i < n; ++i) {
      while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 1e-9F) --k;
      h[k++] = p[i];
    }
    for (std::size_t i = n - 1, t = k + 1; i-- > 0;) {
      while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 1e-9F) --k;
      h[k++] = p[i];
    }
    const std::size_t size = k > 1 ? k - 1 : k;
    const std::size_t kept = std::min(size, kMaxHullVertices);
    std::copy(h, h + kept, out);
    return kept;
  }

  bool load_model(const XMLElement* model) {
    const char* name = model->Attribute("name") != nullptr ? model->Attribute("name") : "";
    RigidTransform model_pose;
    if (!parse_pose(model, model_pose, errors)) return false;
    for (const XMLElement* e = model->FirstChildElement(); e != nullptr;
         e = e->NextSiblingElement()) {
      if (is_name(e, "model")) {
        return errors.fail(e->GetLineNum(), "nested <model> is not supported");
      }
      if (is_name(e, "include")) {
        return errors.fail(e->GetLineNum(), "<include> inside a model is not supported");
      }
    }
    for (const XMLElement* link = model->FirstChildElement("link"); link != nullptr;
         link = link->NextSiblingElement("link")) {
      RigidTransform link_pose;
      if (!parse_pose(link, link_pose, errors)) return false;
      const RigidTransform world_from_link = model_pose.then(link_pose);
      bool has_collision = false;
      for (const XMLElement* c = link->FirstChildElement("collision"); c != nullptr;
           c = c->NextSiblingElement("collision")) {
        has_collision = true;
        if (!load_collision(c, world_from_link, name)) return false;
      }
      for (const XMLElement* v = link->FirstChildElement("visual"); v != nullptr;
           v = v->NextSiblingElement("visual")) {
        const std::size_t index = world.surface_count;
        if (!load_visual(v, world_from_link, name)) return false;
        const Surface& s = world.surfaces[index];
        if (!has_collision && s.shape != Shape::kPlane) {
          // A link without collision elements collides with its visuals.
          RigidTransform t = s.world_from_local;
          if (!add_collider(s.shape, s.half_size_m, t, name, s.line)) return false;
        }
      }
    }
    return true;
  }

  bool load_include(const XMLElement* include, bool& have_robot) {
    const XMLElement* uri = required_child(include, "uri", errors);
    if (uri == nullptr) return false;
    const char* text = uri->GetText() != nullptr ? uri->GetText() : "";
    while (*text == ' ' || *text == '\n' || *text == '\t' || *text == '\r') ++text;
    if (std::strncmp(text, "model://boticelli", 17) != 0 ||
        (text[17] != '\0' && text[17] != ' ' && text[17] != '\n' && text[17] != '\t' &&
         text[17] != '\r' && text[17] != '/')) {
      return true;  // other includes (sun, ground_plane, ...) are not part of the subset
    }
    if (have_robot) {
      return errors.fail(include->GetLineNum(), "a second robot <include> (exactly one allowed)");
    }
    have_robot = true;
    const XMLElement* pose = include->FirstChildElement("pose");
    float v[6] = {};
    if (pose != nullptr && !parse_numbers(pose, v, 6, 6, errors)) return false;
    if (std::fabs(v[0]) > kMaxCoordinate_m || std::fabs(v[1]) > kMaxCoordinate_m) {
      return errors.fail(pose->GetLineNum(), "robot start is beyond %g m",
                         static_cast<double>(kMaxCoordinate_m));
    }
    world.start = {v[0], v[1], std::remainder(v[5], 6.2831853F)};
    return true;
  }

  bool load(const tinyxml2::XMLDocument& doc) {
    const XMLElement* sdf = doc.RootElement();
    if (sdf == nullptr || !is_name(sdf, "sdf")) {
      return errors.fail(sdf != nullptr ? sdf->GetLineNum() : 1, "the root element is not <sdf>");
    }
    const XMLElement* w = required_child(sdf, "world", errors);
    if (w == nullptr) return false;
    std::snprintf(world.name, sizeof world.name, "%s",
                  w->Attribute("name") != nullptr ? w->Attribute("name") : "");
    if (const XMLElement* scene = w->FirstChildElement("scene"); scene != nullptr) {
      if (const XMLElement* a = scene->FirstChildElement("ambient"); a != nullptr) {
        if (!parse_colour(a, world.ambient, errors)) return false;
      }
    }
    bool have_light = false;
    for (const XMLElement* light = w->FirstChildElement("light"); light != nullptr;
         light = light->NextSiblingElement("light")) {
      const char* type = light->Attribute("type");
      if (type == nullptr || std::strcmp(type, "directional") != 0) continue;
      if (have_light) {
        return errors.fail(light->GetLineNum(), "a second directional <light> (at most one)");
      }
      have_light = true;
      if (const XMLElement* d = light->FirstChildElement("direction"); d != nullptr) {
        float v[3];
        if (!parse_numbers(d, v, 3, 3, errors)) return false;
        const Eigen::Vector3f dir(v[0], v[1], v[2]);
        if (dir.norm() < 1e-6F) return errors.fail(d->GetLineNum(), "<direction> is zero");
        world.light_direction = dir.normalized();
      }
      if (const XMLElement* d = light->FirstChildElement("diffuse"); d != nullptr) {
        if (!parse_colour(d, world.light_diffuse, errors)) return false;
      }
    }
    bool have_robot = false;
    for (const XMLElement* e = w->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
      if (is_name(e, "include")) {
        if (!load_include(e, have_robot)) return false;
      } else if (is_name(e, "model")) {
        if (!load_model(e)) return false;
      }
    }
    if (!have_robot) {
      return errors.fail(w->GetLineNum(),
                         "no robot: <include><uri>model://boticelli</uri> is required");
    }
    if (targets == 0) {
      return errors.fail(w->GetLineNum(), "no <boticelli:target> (exactly one is required)");
    }
    for (std::size_t i = 0; i < world.surface_count; ++i) {
      const Surface& s = world.surfaces[i];
      if (s.target_face == kNoFace) continue;
      const TargetFace f = target_face_frame(s);
      // Centroid at the face centre; the upper vertex is one circumradius (size/sqrt 3) above.
      world.target_point_m = f.centre_m + f.up * (s.target_size_m / std::sqrt(3.0F));
      world.target_normal = f.normal;
      world.target_surface = i;
    }
    return true;
  }
};

}  // namespace

bool parse_world(const char* xml, std::size_t size, const char* file_label, World& world,
                 char* error, std::size_t error_size) {
  Errors errors(file_label, error, error_size);
  if (size > kMaxWorldFileBytes) {
    return errors.fail(1, "the file is larger than %zu bytes", kMaxWorldFileBytes);
  }
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml, size) != tinyxml2::XML_SUCCESS) {
    return errors.fail(doc.ErrorLineNum(), "malformed XML: %s", doc.ErrorStr());
  }
  world = World{};
  Loader loader{world, errors};
  if (!loader.load(doc)) {
    world = World{};
    return false;
  }
  return true;
}

bool load_world(const char* path, World& world, char* error, std::size_t error_size) {
  Errors errors(path, error, error_size);
  std::FILE* f = std::fopen(path, "rb");
  if (f == nullptr) return errors.fail(0, "cannot open the world file: %s", std::strerror(errno));
  const std::size_t limit = kMaxWorldFileBytes + 1;
  std::unique_ptr<char[]> text(new char[limit]);
  const std::size_t n = std::fread(text.get(), 1, limit, f);
  const bool read_error = std::ferror(f) != 0;
  const int read_errno = errno;
  std::fclose(f);
  if (read_error) {
    return errors.fail(0, "cannot read the world file: %s", std::strerror(read_errno));
  }
  return parse_world(text.get(), n, path, world, error, error_size);
}

}  // namespace boticelli::hal::sim
