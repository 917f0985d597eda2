// Array helpers shared by the bindings: input array types, shape checks and numpy arrays that own
// their std::vector.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace wv::bindings {

namespace nb = nanobind;

using F64In = nb::ndarray<const double, nb::c_contig, nb::device::cpu>;
using I32In = nb::ndarray<const int32_t, nb::c_contig, nb::device::cpu>;

template <class T>
nb::object to_numpy(std::vector<T>&& v, std::vector<size_t> shape) {
  if (v.empty()) v.reserve(1);
  auto* heap = new std::vector<T>(std::move(v));
  nb::capsule owner(heap, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  return nb::cast(nb::ndarray<nb::numpy, T>(heap->data(), shape.size(), shape.data(), owner));
}

inline void check_rows(const F64In& a, size_t n, const char* what) {
  if (a.ndim() != 2 || a.shape(0) != n || a.shape(1) != 3)
    throw std::invalid_argument(std::string(what) + " must have shape (n, 3)");
}

inline std::vector<double> copy1(const F64In& a, size_t expected, const char* what) {
  if (a.ndim() != 1 || a.shape(0) != expected)
    throw std::invalid_argument(std::string(what) + " must have shape (" + std::to_string(expected) + ",)");
  return std::vector<double>(a.data(), a.data() + expected);
}

}  // namespace wv::bindings
