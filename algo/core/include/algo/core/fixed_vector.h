// Fixed-capacity vector: storage inside the object, no heap, overflow reported not thrown.
#pragma once

#include <array>
#include <cassert>
#include <cstddef>
#include <span>
#include <type_traits>

namespace boticelli::core {

// The size-free base (like etl::ivector): functions take FixedVectorBase<T>& so they are
// not templated on capacity. T must be default-constructible and copy-assignable; the
// storage is a std::array, so elements past size() exist but are not part of the vector.
template <typename T>
class FixedVectorBase {
 public:
  FixedVectorBase(const FixedVectorBase&) = delete;
  FixedVectorBase& operator=(const FixedVectorBase&) = delete;

  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] std::size_t capacity() const { return capacity_; }
  [[nodiscard]] bool empty() const { return size_ == 0; }
  [[nodiscard]] bool full() const { return size_ == capacity_; }

  // The one overflow policy: a push into a full vector is refused and returns false.
  [[nodiscard]] bool push_back(const T& value) {
    if (size_ == capacity_) {
      return false;
    }
    data_[size_++] = value;
    return true;
  }
  void pop_back() {
    if (size_ > 0) {
      --size_;
    }
  }
  void clear() { size_ = 0; }
  // Shrinks, or grows up to capacity with value-initialised elements; returns the size after.
  std::size_t resize(std::size_t n) {
    if (n > capacity_) {
      n = capacity_;
    }
    for (std::size_t i = size_; i < n; ++i) {
      data_[i] = T{};
    }
    size_ = n;
    return size_;
  }

  // Appends, and when full first keeps every other element (the first, the third, ...): a
  // history that stays whole from its beginning at half the resolution (FixedVector has a
  // capacity of at least 1, so this always appends).
  bool push_back_thinning(const T& value) {
    if (size_ == capacity_) {
      std::size_t kept = 0;
      for (std::size_t i = 0; i < size_; i += 2) data_[kept++] = data_[i];
      size_ = kept;
    }
    return push_back(value);
  }

  // Indices are checked where assertions are on (the asan preset, a Debug build): an element
  // past size() is no element of the vector, even though its storage exists.
  T& operator[](std::size_t i) {
    assert(i < size_);
    return data_[i];
  }
  const T& operator[](std::size_t i) const {
    assert(i < size_);
    return data_[i];
  }
  T& back() {
    assert(size_ > 0);
    return data_[size_ - 1];
  }
  const T& back() const {
    assert(size_ > 0);
    return data_[size_ - 1];
  }
  T* begin() { return data_; }
  T* end() { return data_ + size_; }
  const T* begin() const { return data_; }
  const T* end() const { return data_ + size_; }
  T* data() { return data_; }
  const T* data() const { return data_; }
  std::span<T> span() { return {data_, size_}; }
  std::span<const T> span() const { return {data_, size_}; }

 protected:
  FixedVectorBase(T* data, std::size_t capacity) : data_(data), capacity_(capacity) {}
  ~FixedVectorBase() = default;

 private:
  T* data_;
  std::size_t capacity_;
  std::size_t size_ = 0;
};

namespace detail {
// Holds the elements; a base listed before FixedVectorBase so it is built first.
template <typename T, std::size_t N>
struct FixedStorage {
  std::array<T, N> storage_{};
};
}  // namespace detail

// Adds the storage: FixedVector<Reading, 4096> readings;
template <typename T, std::size_t N>
class FixedVector final : private detail::FixedStorage<T, N>, public FixedVectorBase<T> {
  static_assert(N > 0, "a fixed vector needs a capacity");
  static_assert(std::is_default_constructible_v<T>, "elements are stored in a std::array");

 public:
  FixedVector() : FixedVectorBase<T>(this->storage_.data(), N) {}
  FixedVector(const FixedVector& other) : FixedVectorBase<T>(this->storage_.data(), N) {
    *this = other;
  }
  FixedVector& operator=(const FixedVector& other) {
    if (this != &other) {
      this->clear();
      for (const T& v : other) {
        (void)this->push_back(v);
      }
    }
    return *this;
  }
  static constexpr std::size_t kCapacity = N;
};

}  // namespace boticelli::core
