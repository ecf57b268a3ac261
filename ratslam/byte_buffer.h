// Little binary encoding of state for map files: trivially copyable values, counts, strings and
// vectors. The reader checks every count against the bytes left, so corrupt or truncated input
// is an error, never a crash or a huge allocation. Host byte order (files move between machines
// of one architecture).
#ifndef RATSLAM_BYTE_BUFFER_H_
#define RATSLAM_BYTE_BUFFER_H_

#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

namespace ratslam {

class ByteWriter {
 public:
  template <typename T>
  void Pod(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof(T));
  }
  void Bool(bool v) { Pod<uint8_t>(v ? 1 : 0); }
  void Optional(const std::optional<double>& v) {
    Bool(v.has_value());
    Pod(v.value_or(0.0));
  }
  void Count(size_t n) { Pod<uint64_t>(n); }
  void String(const std::string& s) {
    Count(s.size());
    bytes_.append(s);
  }
  template <typename T>
  void PodVector(const std::vector<T>& v) {
    Count(v.size());
    if (!v.empty()) bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  // `context` starts every error message.
  ByteReader(const std::string& bytes, std::string context)
      : bytes_(bytes), context_(std::move(context)) {}
  template <typename T>
  bool Pod(T* value) {
    static_assert(std::is_trivially_copyable_v<T>);
    if (!Need(sizeof(T))) return false;
    std::memcpy(value, bytes_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  bool Bool(bool* v) {
    uint8_t b = 0;
    if (!Pod(&b)) return false;
    if (b > 1) return Fail("invalid boolean");
    *v = b == 1;
    return true;
  }
  bool Optional(std::optional<double>* v) {
    bool has = false;
    double value = 0.0;
    if (!(Bool(&has) && Pod(&value))) return false;
    *v = has ? std::optional<double>(value) : std::nullopt;
    return true;
  }
  // A count of elements of `element_size` bytes each; fails if they cannot all be present.
  bool Count(size_t element_size, size_t* n) {
    uint64_t count = 0;
    if (!Pod(&count)) return false;
    if (element_size > 0 && count > (bytes_.size() - pos_) / element_size) {
      return Fail("count " + std::to_string(count) + " exceeds the file size (truncated?)");
    }
    *n = static_cast<size_t>(count);
    return true;
  }
  bool String(std::string* s) {
    size_t n = 0;
    if (!Count(1, &n)) return false;
    s->assign(bytes_.data() + pos_, n);
    pos_ += n;
    return true;
  }
  template <typename T>
  bool PodVector(std::vector<T>* v) {
    size_t n = 0;
    if (!Count(sizeof(T), &n)) return false;
    v->resize(n);
    if (n) std::memcpy(v->data(), bytes_.data() + pos_, n * sizeof(T));
    pos_ += n * sizeof(T);
    return true;
  }
  bool Fail(const std::string& message) {
    if (error_.empty()) {
      error_ = context_ + " at byte " + std::to_string(pos_) + ": " + message;
    }
    return false;
  }
  bool AtEnd() const { return pos_ == bytes_.size(); }
  const std::string& error() const { return error_; }

 private:
  bool Need(size_t n) {
    if (bytes_.size() - pos_ < n) return Fail("unexpected end of file (truncated?)");
    return true;
  }
  const std::string& bytes_;
  std::string context_;
  size_t pos_ = 0;
  std::string error_;
};

}  // namespace ratslam

#endif  // RATSLAM_BYTE_BUFFER_H_
