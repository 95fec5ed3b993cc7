// Byte streams for files that only floesim reads back (the simulation's checkpoints): values in the host's layout
// (a checkpoint is resumed by the same build on the same kind of machine; its header says which build wrote it),
// written field by field (no struct padding, so equal states give equal bytes), and read with every length checked,
// so that a damaged file gives an error, never a crash or a silent wrong value.
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "pipeline/error.h"

namespace floesim {

class ByteWriter {
 public:
  template <class T>
  void pod(const T& v) {
    static_assert(std::is_arithmetic_v<T>, "ByteWriter::pod takes numbers; write structs field by field");
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void size(size_t n) { pod<uint64_t>(n); }
  void str(const std::string& s) {
    size(s.size());
    bytes_ += s;
  }
  template <class T>
  void vec(const std::vector<T>& v, size_t first = 0) {  // elements [first, size)
    static_assert(std::is_arithmetic_v<T>, "ByteWriter::vec takes vectors of numbers");
    size(v.size() - first);
    if (v.size() > first) bytes_.append(reinterpret_cast<const char*>(v.data() + first), (v.size() - first) * sizeof(T));
  }
  template <class Derived>
  void mat(const Eigen::MatrixBase<Derived>& m) {  // a fixed-size Eigen matrix or vector, column-major
    for (Eigen::Index i = 0; i < m.size(); ++i) pod<double>(m.derived().data()[i]);
  }
  void quat(const Eigen::Quaterniond& q) { mat(q.coeffs()); }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  // `what` names the file in errors ("...: damaged or not a floesim checkpoint").
  ByteReader(const std::string& bytes, std::string what)
      : begin_(bytes.data()), p_(bytes.data()), end_(bytes.data() + bytes.size()), what_(std::move(what)) {}
  template <class T>
  T pod() {
    static_assert(std::is_arithmetic_v<T>);
    need(sizeof(T));
    T v;
    std::memcpy(&v, p_, sizeof v);
    p_ += sizeof v;
    return v;
  }
  size_t size(size_t max_elements_of_bytes = 1) {
    const uint64_t n = pod<uint64_t>();
    // No length can exceed what is left in the file: a damaged length fails here, not in an allocation.
    FLOESIM_REQUIRE(n <= static_cast<uint64_t>(end_ - p_) / max_elements_of_bytes, what_,
                    ": damaged (a length runs past the end of the file)");
    return static_cast<size_t>(n);
  }
  std::string str() {
    const size_t n = size();
    std::string s(p_, n);
    p_ += n;
    return s;
  }
  template <class T>
  void vec_append(std::vector<T>& v) {  // appends the elements of one vec() record
    const size_t n = size(sizeof(T));
    const size_t at = v.size();
    v.resize(at + n);
    if (n) std::memcpy(v.data() + at, p_, n * sizeof(T));
    p_ += n * sizeof(T);
  }
  // Passes over one vec() record: its element count, its elements starting at `*at` bytes from the start.
  template <class T>
  size_t vec_skip(size_t* at = nullptr) {
    const size_t n = size(sizeof(T));
    if (at) *at = offset();
    p_ += n * sizeof(T);
    return n;
  }
  template <class T>
  std::vector<T> vec() {
    std::vector<T> v;
    vec_append(v);
    return v;
  }
  template <class M>
  void mat(M& m) {
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = pod<double>();
  }
  Eigen::Quaterniond quat() {
    Eigen::Quaterniond q;
    mat(q.coeffs());
    return q;
  }
  bool done() const { return p_ == end_; }
  size_t offset() const { return static_cast<size_t>(p_ - begin_); }  // bytes read so far
  const std::string& what() const { return what_; }

 private:
  void need(size_t n) const {
    FLOESIM_REQUIRE(static_cast<size_t>(end_ - p_) >= n, what_, ": damaged (it ends too early)");
  }
  const char* begin_;
  const char* p_;
  const char* end_;
  std::string what_;
};

}  // namespace floesim
