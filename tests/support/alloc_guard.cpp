// AllocationGuard: wraps CppUTest's allocators, the malloc family and aligned allocation to count
// allocations.
#include "alloc_guard.h"

#include <malloc.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "CppUTest/TestMemoryAllocator.h"

extern "C" {
void* __real_malloc(std::size_t size);
void* __real_calloc(std::size_t n, std::size_t size);
void* __real_realloc(void* p, std::size_t size);
int __real_posix_memalign(void** out, std::size_t alignment, std::size_t size);
void* __real_aligned_alloc(std::size_t alignment, std::size_t size);
void* __real_memalign(std::size_t alignment, std::size_t size);
}

namespace {

std::atomic<bool> g_counting{false};
std::atomic<std::size_t> g_count{0};

// Forwards to the allocator that was current before the guard, counting every alloc.
class CountingAllocator final : public TestMemoryAllocator {
 public:
  void wrap(TestMemoryAllocator* previous) { previous_ = previous; }
  TestMemoryAllocator* previous() const { return previous_; }

  char* alloc_memory(size_t size, const char* file, size_t line) override {
    g_count.fetch_add(1, std::memory_order_relaxed);
    return previous_->alloc_memory(size, file, line);
  }
  void free_memory(char* memory, size_t size, const char* file, size_t line) override {
    previous_->free_memory(memory, size, file, line);
  }
  // Same names as the wrapped allocator, so CppUTest's new/delete pairing check accepts
  // memory allocated before the guard and freed inside it (and vice versa).
  const char* name() const override { return previous_->name(); }
  const char* alloc_name() const override { return previous_->alloc_name(); }
  const char* free_name() const override { return previous_->free_name(); }
  TestMemoryAllocator* actualAllocator() override { return previous_->actualAllocator(); }

 private:
  TestMemoryAllocator* previous_ = nullptr;
};

CountingAllocator g_new_counter;
CountingAllocator g_new_array_counter;
CountingAllocator g_malloc_counter;

}  // namespace

extern "C" {
void* __wrap_malloc(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_count.fetch_add(1, std::memory_order_relaxed);
  }
  return __real_malloc(size);
}
void* __wrap_calloc(std::size_t n, std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_count.fetch_add(1, std::memory_order_relaxed);
  }
  return __real_calloc(n, size);
}
void* __wrap_realloc(void* p, std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_count.fetch_add(1, std::memory_order_relaxed);
  }
  return __real_realloc(p, size);
}
int __wrap_posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_count.fetch_add(1, std::memory_order_relaxed);
  }
  return __real_posix_memalign(out, alignment, size);
}
void* __wrap_aligned_alloc(std::size_t alignment, std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_count.fetch_add(1, std::memory_order_relaxed);
  }
  return __real_aligned_alloc(alignment, size);
}
void* __wrap_memalign(std::size_t alignment, std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_count.fetch_add(1, std::memory_order_relaxed);
  }
  return __real_memalign(alignment, size);
}
}

// Over-aligned new (alignof > __STDCPP_DEFAULT_NEW_ALIGNMENT__, e.g. a struct of alignas(64)
// members): CppUTest replaces only the plain forms, so libstdc++'s would allocate unseen
// (inside libstdc++, out of the wrappers' reach). These replace it, count, and allocate with
// posix_memalign (freed with free, which the matching deletes below do).
// CppUTest's leak-detection `new` macro (from alloc_guard.h) would rename the operators.
#undef new

namespace {
void* aligned_new(std::size_t size, std::align_val_t alignment) {
  if (g_counting.load(std::memory_order_relaxed)) {
    g_count.fetch_add(1, std::memory_order_relaxed);
  }
  auto align = static_cast<std::size_t>(alignment);
  if (align < sizeof(void*)) align = sizeof(void*);
  void* p = nullptr;
  if (__real_posix_memalign(&p, align, size == 0 ? 1 : size) != 0) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t size, std::align_val_t alignment) {
  return aligned_new(size, alignment);
}
void* operator new[](std::size_t size, std::align_val_t alignment) {
  return aligned_new(size, alignment);
}
void* operator new(std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  try {
    return aligned_new(size, alignment);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, std::align_val_t alignment, const std::nothrow_t&) noexcept {
  try {
    return aligned_new(size, alignment);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  std::free(p);
}

namespace boticelli::test {

AllocationGuard::AllocationGuard() {
  g_new_counter.wrap(getCurrentNewAllocator());
  g_new_array_counter.wrap(getCurrentNewArrayAllocator());
  g_malloc_counter.wrap(getCurrentMallocAllocator());
  setCurrentNewAllocator(&g_new_counter);
  setCurrentNewArrayAllocator(&g_new_array_counter);
  setCurrentMallocAllocator(&g_malloc_counter);
  g_count.store(0, std::memory_order_relaxed);
  g_counting.store(true, std::memory_order_relaxed);
}

AllocationGuard::~AllocationGuard() {
  stop();
}

void AllocationGuard::stop() {
  if (!active_) {
    return;
  }
  active_ = false;
  g_counting.store(false, std::memory_order_relaxed);
  setCurrentNewAllocator(g_new_counter.previous());
  setCurrentNewArrayAllocator(g_new_array_counter.previous());
  setCurrentMallocAllocator(g_malloc_counter.previous());
}

std::size_t AllocationGuard::allocations() const {
  return g_count.load(std::memory_order_relaxed);
}

}  // namespace boticelli::test
