// Little binary encoding of state for map files: numbers, counts, strings and vectors of numbers.
// The reader checks every count against the bytes left, so corrupt or truncated input is an
// error, never a crash or a huge allocation. Numbers are little-endian on every host (swapped on
// big-endian ones), so files move between machines.
//
// EncodeArchive and DecodeArchive let one `Describe(archive, object)` function per type both
// write and read it: the field list exists once, so a field cannot be written and not read.
#ifndef RATSLAM_COMMON_BYTE_BUFFER_H_
#define RATSLAM_COMMON_BYTE_BUFFER_H_

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace ratslam {

// Numbers that ByteWriter and ByteReader store: their bytes, little-endian.
template <typename T>
concept ByteNumber = std::is_arithmetic_v<T> || std::is_enum_v<T>;

namespace byte_order {
template <ByteNumber T>
void ToLittleEndian(char* bytes) {
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
}
}  // namespace byte_order

class ByteWriter {
 public:
  template <ByteNumber T>
  void Pod(const T& value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    byte_order::ToLittleEndian<T>(raw);
    bytes_.append(raw, sizeof(T));
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
  template <ByteNumber T>
  void PodVector(const std::vector<T>& v) {
    Count(v.size());
    if constexpr (std::endian::native == std::endian::little) {
      if (!v.empty()) bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    } else {
      for (const T& x : v) Pod(x);
    }
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  // Reads `bytes` in place (no copy; they must outlive the reader). `context` starts every
  // error message.
  ByteReader(std::string_view bytes, std::string context)
      : bytes_(bytes), context_(std::move(context)) {}
  template <ByteNumber T>
  bool Pod(T* value) {
    if (!Need(sizeof(T))) return false;
    char raw[sizeof(T)];
    std::memcpy(raw, bytes_.data() + pos_, sizeof(T));
    byte_order::ToLittleEndian<T>(raw);
    std::memcpy(value, raw, sizeof(T));
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
  template <ByteNumber T>
  bool PodVector(std::vector<T>* v) {
    size_t n = 0;
    if (!Count(sizeof(T), &n)) return false;
    v->resize(n);
    if constexpr (std::endian::native == std::endian::little) {
      if (n) std::memcpy(v->data(), bytes_.data() + pos_, n * sizeof(T));
      pos_ += n * sizeof(T);
      return true;
    } else {
      for (T& x : *v) {
        if (!Pod(&x)) return false;
      }
      return true;
    }
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
  std::string_view bytes_;
  std::string context_;
  size_t pos_ = 0;
  std::string error_;
};

// Writes what a Describe function lists. Every call succeeds; checks are for decoding.
class EncodeArchive {
 public:
  // `version`: the format version being written (Describe functions may list a field only from
  // the version that introduced it).
  EncodeArchive(ByteWriter& writer, uint32_t version) : w_(writer), version_(version) {}
  uint32_t version() const { return version_; }
  template <ByteNumber T>
  bool operator()(T& v) {
    w_.Pod(v);
    return true;
  }
  bool operator()(bool& v) {
    w_.Bool(v);
    return true;
  }
  bool operator()(std::string& v) {
    w_.String(v);
    return true;
  }
  template <ByteNumber T>
  bool operator()(std::optional<T>& v) {
    w_.Bool(v.has_value());
    w_.Pod(v.value_or(T{}));
    return true;
  }
  template <ByteNumber T>
  bool operator()(std::vector<T>& v) {
    w_.PodVector(v);
    return true;
  }
  // A nested object, described by its own Describe.
  template <typename T>
  bool Object(T& v) {
    return Describe(*this, v);
  }
  // A vector of described objects, each at least `min_bytes` long encoded.
  template <typename T>
  bool Objects(std::vector<T>& v, size_t /*min_bytes*/) {
    w_.Count(v.size());
    for (T& x : v) Describe(*this, x);
    return true;
  }
  bool Check(bool, const char*) { return true; }

 private:
  ByteWriter& w_;
  uint32_t version_;
};

// Reads what a Describe function lists; the first failure stops it (see ByteReader::error).
class DecodeArchive {
 public:
  // `version`: the format version of the bytes (read from their header); older versions lack
  // the fields added since, which keep their defaults (migration).
  DecodeArchive(ByteReader& reader, uint32_t version) : r_(reader), version_(version) {}
  uint32_t version() const { return version_; }
  template <ByteNumber T>
  bool operator()(T& v) {
    return r_.Pod(&v);
  }
  bool operator()(bool& v) { return r_.Bool(&v); }
  bool operator()(std::string& v) { return r_.String(&v); }
  template <ByteNumber T>
  bool operator()(std::optional<T>& v) {
    bool has = false;
    T value{};
    if (!(r_.Bool(&has) && r_.Pod(&value))) return false;
    v = has ? std::optional<T>(value) : std::nullopt;
    return true;
  }
  template <ByteNumber T>
  bool operator()(std::vector<T>& v) {
    return r_.PodVector(&v);
  }
  template <typename T>
  bool Object(T& v) {
    return Describe(*this, v);
  }
  template <typename T>
  bool Objects(std::vector<T>& v, size_t min_bytes) {
    size_t n = 0;
    if (!r_.Count(min_bytes, &n)) return false;
    v.resize(n);
    for (T& x : v) {
      if (!Describe(*this, x)) return false;
    }
    return true;
  }
  // A condition on what was just read (an enum's range, say); false fails with `what`.
  bool Check(bool ok, const char* what) { return ok || r_.Fail(what); }

 private:
  ByteReader& r_;
  uint32_t version_;
};

// A string as an object of a schema (e.g. a list of strings through Objects).
template <typename A>
bool Describe(A& a, std::string& s) {
  return a(s);
}

}  // namespace ratslam

#endif  // RATSLAM_COMMON_BYTE_BUFFER_H_
