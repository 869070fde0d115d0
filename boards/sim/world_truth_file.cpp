// WorldTruthFile: the simulated world's state in a shared mapping, two checksummed slots.
#include "world_truth_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace boticelli::boards::sim {
namespace {

constexpr char kMagic[8] = {'B', 'O', 'T', 'S', 'I', 'M', 'W', '1'};

std::uint64_t fnv(std::uint64_t h, const void* data, std::size_t size) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 0x100000001B3ULL;
  }
  return h;
}
constexpr std::uint64_t kFnvBasis = 0xCBF29CE484222325ULL;

std::uint64_t slot_checksum(const WorldTruthFile::Slot& s) {
  return fnv(fnv(kFnvBasis, &s.sequence, sizeof s.sequence), s.values, sizeof s.values);
}

void to_values(const hal::sim::SimWorld::PhysicalState& st, double (&v)[7]) {
  v[0] = st.x_m;
  v[1] = st.y_m;
  v[2] = st.yaw_rad;
  v[3] = st.wheel_left_m;
  v[4] = st.wheel_right_m;
  v[5] = static_cast<double>(st.wheel_left_m_s);
  v[6] = static_cast<double>(st.wheel_right_m_s);
}

}  // namespace

std::uint64_t WorldTruthFile::world_id(const hal::sim::World& world) {
  std::uint64_t h = fnv(kFnvBasis, &world.start, sizeof world.start);
  for (std::size_t i = 0; i < world.collider_count; ++i) {
    const hal::sim::Collider& c = world.colliders[i];
    const float shape[4] = {c.centre_x_m, c.centre_y_m, c.radius_m,
                            static_cast<float>(c.hull_size)};
    h = fnv(h, shape, sizeof shape);
    for (std::size_t k = 0; k < c.hull_size; ++k) h = fnv(h, &c.hull[k], sizeof c.hull[k]);
  }
  return h;
}

WorldTruthFile::Load WorldTruthFile::load(const char* path, std::uint64_t world_id,
                                          hal::sim::SimWorld::PhysicalState& out, char* why,
                                          std::size_t why_size) {
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
  if (fd < 0) {
    std::snprintf(why, why_size, "%s: %s", path, std::strerror(errno));
    return errno == ENOENT ? Load::kMissing : Load::kDamaged;
  }
  Layout layout{};
  const ssize_t n = ::read(fd, &layout, sizeof layout);
  ::close(fd);
  if (n != static_cast<ssize_t>(sizeof layout) || std::memcmp(layout.magic, kMagic, 8) != 0) {
    std::snprintf(why, why_size, "%s: not a simulated world's state", path);
    return Load::kDamaged;
  }
  if (layout.world_id != world_id) {
    std::snprintf(why, why_size, "%s: the state of another world", path);
    return Load::kOtherWorld;
  }
  const Slot* best = nullptr;
  for (const Slot& s : layout.slots) {
    if (s.sequence == 0 || s.checksum != slot_checksum(s)) continue;
    if (best == nullptr || s.sequence > best->sequence) best = &s;
  }
  if (best == nullptr) {
    std::snprintf(why, why_size, "%s: no whole record", path);
    return Load::kDamaged;
  }
  const double* v = best->values;
  out.x_m = v[0];
  out.y_m = v[1];
  out.yaw_rad = v[2];
  out.wheel_left_m = v[3];
  out.wheel_right_m = v[4];
  out.wheel_left_m_s = static_cast<float>(v[5]);
  out.wheel_right_m_s = static_cast<float>(v[6]);
  return Load::kLoaded;
}

bool WorldTruthFile::open(const char* path, std::uint64_t world_id, char* error,
                          std::size_t error_size) {
  close();
  const int fd = ::open(path, O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd < 0) {
    std::snprintf(error, error_size, "%s: %s", path, std::strerror(errno));
    return false;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) ||
      ::ftruncate(fd, static_cast<off_t>(sizeof(Layout))) != 0) {
    std::snprintf(error, error_size, "%s: not a regular file that can be sized", path);
    ::close(fd);
    return false;
  }
  void* map = ::mmap(nullptr, sizeof(Layout), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);  // the mapping keeps the file
  if (map == MAP_FAILED) {
    std::snprintf(error, error_size, "%s: mmap: %s", path, std::strerror(errno));
    return false;
  }
  map_ = static_cast<Layout*>(map);
  std::memset(map_, 0, sizeof(Layout));
  std::memcpy(map_->magic, kMagic, 8);
  map_->world_id = world_id;
  sequence_ = 0;
  return true;
}

void WorldTruthFile::record(const hal::sim::SimWorld::PhysicalState& state) {
  if (map_ == nullptr) return;
  ++sequence_;
  Slot& slot = map_->slots[sequence_ & 1U];
  slot.sequence = 0;  // invalid while it is written
  std::atomic_signal_fence(std::memory_order_seq_cst);
  to_values(state, slot.values);
  Slot whole = slot;
  whole.sequence = sequence_;
  slot.checksum = slot_checksum(whole);
  std::atomic_signal_fence(std::memory_order_seq_cst);
  slot.sequence = sequence_;
}

void WorldTruthFile::close() {
  if (map_ == nullptr) return;
  ::munmap(map_, sizeof(Layout));
  map_ = nullptr;
}

}  // namespace boticelli::boards::sim
