#include "dataset/descriptor_file.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string_view>

#include "common/file_util.h"
#include "common/text_file.h"

namespace ratslam::dataset {
namespace {

Status ValueError(const std::string& where, const std::string& message) {
  return Status::Error(where + ": " + message);
}

// A finite value in float range, else why not.
std::optional<std::string> BadValue(double v) {
  if (!std::isfinite(v)) return std::string("not finite");
  if (std::abs(v) > static_cast<double>(std::numeric_limits<float>::max())) {
    return std::string("out of float range");
  }
  return std::nullopt;
}

// NumPy's header is a Python dict literal: {'descr': '<f4', 'fortran_order': False, 'shape': (3,
// 4), } padded with spaces and a newline. A small strict parser of exactly that grammar.
class NpyHeaderParser {
 public:
  explicit NpyHeaderParser(std::string_view text) : text_(text) {}

  Status Parse(std::string* descr, bool* fortran, std::vector<uint64_t>* shape) {
    bool have_descr = false, have_fortran = false, have_shape = false;
    if (!Eat('{')) return Error("expected '{'");
    for (;;) {
      if (Eat('}')) break;
      std::string key;
      if (!String(&key)) return Error("expected a quoted key");
      if (!Eat(':')) return Error("expected ':' after '" + key + "'");
      if (key == "descr" && !have_descr) {
        if (!String(descr)) return Error("'descr' is not a string");
        have_descr = true;
      } else if (key == "fortran_order" && !have_fortran) {
        if (Word("True")) {
          *fortran = true;
        } else if (Word("False")) {
          *fortran = false;
        } else {
          return Error("'fortran_order' is neither True nor False");
        }
        have_fortran = true;
      } else if (key == "shape" && !have_shape) {
        if (!Shape(shape)) return Error("'shape' is not a tuple of non-negative integers");
        have_shape = true;
      } else {
        return Error("unexpected or repeated key '" + key + "'");
      }
      if (Eat(',')) continue;
      if (Eat('}')) break;
      return Error("expected ',' or '}'");
    }
    SkipSpace();
    if (pos_ != text_.size()) return Error("text after the closing '}'");
    if (!have_descr || !have_fortran || !have_shape) {
      return Error("needs 'descr', 'fortran_order' and 'shape'");
    }
    return Status::Ok();
  }

 private:
  Status Error(const std::string& what) const {
    return Status::Error("header at character " + std::to_string(pos_) + ": " + what);
  }
  void SkipSpace() {
    while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\n')) ++pos_;
  }
  bool Eat(char c) {
    SkipSpace();
    if (pos_ < text_.size() && text_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  bool Word(std::string_view word) {
    SkipSpace();
    if (text_.substr(pos_, word.size()) != word) return false;
    pos_ += word.size();
    return true;
  }
  bool String(std::string* out) {
    SkipSpace();
    if (pos_ >= text_.size() || (text_[pos_] != '\'' && text_[pos_] != '"')) return false;
    const char quote = text_[pos_++];
    const size_t end = text_.find(quote, pos_);
    if (end == std::string_view::npos) return false;
    *out = std::string(text_.substr(pos_, end - pos_));
    pos_ = end + 1;
    return true;
  }
  bool Shape(std::vector<uint64_t>* shape) {
    shape->clear();
    if (!Eat('(')) return false;
    for (;;) {
      if (Eat(')')) return true;
      SkipSpace();
      uint64_t n = 0;
      const char* begin = text_.data() + pos_;
      const auto result = std::from_chars(begin, text_.data() + text_.size(), n);
      if (result.ec != std::errc() || result.ptr == begin) return false;
      pos_ += static_cast<size_t>(result.ptr - begin);
      shape->push_back(n);
      if (shape->size() > 8) return false;
      if (Eat(',')) continue;
      return Eat(')');
    }
  }

  std::string_view text_;
  size_t pos_ = 0;
};

uint64_t LittleEndian(const std::string& bytes, size_t at, size_t width) {
  uint64_t v = 0;
  for (size_t i = 0; i < width; ++i) {
    v |= static_cast<uint64_t>(static_cast<unsigned char>(bytes[at + i])) << (8 * i);
  }
  return v;
}

StatusOr<DescriptorMatrix> ParseNpy(const std::string& bytes, const std::string& name) {
  static constexpr char kMagic[] = "\x93NUMPY";
  if (bytes.size() < 10 || bytes.compare(0, 6, kMagic, 6) != 0) {
    return ValueError(name, "not a .npy file (no \\x93NUMPY magic)");
  }
  const int major = static_cast<unsigned char>(bytes[6]);
  if (major < 1 || major > 3) {
    return ValueError(name, ".npy format version " + std::to_string(major) + " is not 1, 2 or 3");
  }
  const size_t width = major == 1 ? 2 : 4;
  if (bytes.size() < 8 + width) return ValueError(name, "truncated .npy header");
  const uint64_t header_len = LittleEndian(bytes, 8, width);
  const size_t data_start = 8 + width;
  if (header_len > bytes.size() - data_start) return ValueError(name, "truncated .npy header");
  std::string descr;
  bool fortran = false;
  std::vector<uint64_t> shape;
  Status header = NpyHeaderParser(std::string_view(bytes).substr(data_start, header_len))
                      .Parse(&descr, &fortran, &shape);
  if (!header.ok()) return header.WithContext(name);
  size_t item = 0;
  if (descr == "<f4") {
    item = 4;
  } else if (descr == "<f8") {
    item = 8;
  } else {
    return ValueError(name, "dtype '" + descr +
                                "' is not float32 or float64 little-endian ('<f4' or '<f8'): "
                                "save with numpy.asarray(x, dtype=numpy.float32)");
  }
  if (shape.size() != 2) {
    return ValueError(name, "the array has " + std::to_string(shape.size()) +
                                " dimensions; descriptors are a 2-D array (frames, dimensions)");
  }
  const uint64_t rows = shape[0], cols = shape[1];
  if (cols == 0) return ValueError(name, "descriptors have zero dimensions");
  if (rows == 0) return ValueError(name, "no descriptors (the array has zero rows)");
  const uint64_t payload = bytes.size() - data_start - header_len;
  // rows * cols * item must equal the payload; checked by division so that no product overflows
  // (cols <= payload keeps cols * item far below 2^64).
  if (cols > payload || payload % (cols * item) != 0 || payload / (cols * item) != rows) {
    return ValueError(name, "shape (" + std::to_string(rows) + ", " + std::to_string(cols) +
                                ") needs " + (cols <= payload ? "" : "more than ") +
                                "the data bytes present (" + std::to_string(payload) +
                                "): truncated or padded file");
  }
  DescriptorMatrix m;
  m.rows = static_cast<size_t>(rows);
  m.cols = static_cast<size_t>(cols);
  m.values.resize(m.rows * m.cols);
  const char* data = bytes.data() + data_start + header_len;
  for (size_t i = 0; i < m.values.size(); ++i) {
    double v = 0.0;
    if (item == 4) {
      float f = 0.0f;
      std::memcpy(&f, data + 4 * i, 4);
      v = f;
    } else {
      std::memcpy(&v, data + 8 * i, 8);
    }
    // Fortran order stores column after column.
    const size_t row = fortran ? i % m.rows : i / m.cols;
    const size_t col = fortran ? i / m.rows : i % m.cols;
    if (const auto bad = BadValue(v)) {
      return ValueError(
          name, "row " + std::to_string(row) + ", column " + std::to_string(col) + ": " + *bad);
    }
    m.values[row * m.cols + col] = static_cast<float>(v);
  }
  return m;
}

std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t start = 0;
  for (;;) {
    const size_t comma = line.find(',', start);
    std::string_view f =
        line.substr(start, comma == std::string_view::npos ? line.npos : comma - start);
    while (!f.empty() && (f.front() == ' ' || f.front() == '\t')) f.remove_prefix(1);
    while (!f.empty() && (f.back() == ' ' || f.back() == '\t')) f.remove_suffix(1);
    fields.push_back(f);
    if (comma == std::string_view::npos) return fields;
    start = comma + 1;
  }
}

std::optional<double> Number(std::string_view text) {
  double v = 0.0;
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, v);
  if (text.empty() || result.ec != std::errc() || result.ptr != end) return std::nullopt;
  return v;
}

StatusOr<DescriptorMatrix> ParseCsv(const std::string& bytes, const std::string& name) {
  DescriptorMatrix m;
  size_t start = 0;
  int line_number = 0;
  bool first = true;
  while (start < bytes.size()) {
    size_t end = bytes.find('\n', start);
    if (end == std::string::npos) end = bytes.size();
    std::string_view line(bytes.data() + start, end - start);
    start = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::string where = name + ":" + std::to_string(line_number);
    if (line.empty()) return ValueError(where, "empty line (one line per frame)");
    if (line.size() > kMaxLineBytes) return ValueError(where, "line longer than 1 MiB");
    const std::vector<std::string_view> fields = SplitFields(line);
    if (first) {
      first = false;
      m.cols = fields.size();
      if (!Number(fields[0])) continue;  // a header
    }
    if (fields.size() != m.cols) {
      return ValueError(where, std::to_string(fields.size()) + " fields, expected " +
                                   std::to_string(m.cols) + " (as on the first line)");
    }
    for (size_t c = 0; c < fields.size(); ++c) {
      const std::optional<double> v = Number(fields[c]);
      if (!v) {
        return ValueError(where, "column " + std::to_string(c + 1) + ": not a number: '" +
                                     std::string(fields[c].substr(0, 40)) + "'");
      }
      if (const auto bad = BadValue(*v)) {
        return ValueError(where, "column " + std::to_string(c + 1) + ": " + *bad + ": '" +
                                     std::string(fields[c]) + "'");
      }
      m.values.push_back(static_cast<float>(*v));
    }
    ++m.rows;
  }
  if (m.rows == 0) return ValueError(name, "no descriptors (the file has no data line)");
  return m;
}

}  // namespace

StatusOr<DescriptorMatrix> ParseDescriptors(const std::string& bytes, const std::string& name,
                                            bool npy) {
  return npy ? ParseNpy(bytes, name) : ParseCsv(bytes, name);
}

StatusOr<DescriptorMatrix> ReadDescriptorFile(const std::string& path) {
  StatusOr<std::string> bytes = ReadRegularFile(path, "descriptor file", kMaxDescriptorFileBytes);
  if (!bytes.ok()) return bytes.status();
  const bool npy = std::filesystem::path(path).extension() == ".npy";
  return ParseDescriptors(*bytes, path, npy);
}

Status WriteDescriptorNpy(const DescriptorMatrix& m, const std::string& path) {
  if (m.values.size() != m.rows * m.cols) {
    return Status::Error(path + ": descriptor matrix has " + std::to_string(m.values.size()) +
                         " values, not rows * cols");
  }
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" +
                       std::to_string(m.rows) + ", " + std::to_string(m.cols) + "), }";
  // Magic, version, length and header end on a multiple of 64 bytes, the header with '\n'.
  const size_t total = 10 + header.size() + 1;
  header.append((64 - total % 64) % 64, ' ');
  header.push_back('\n');
  std::string bytes("\x93NUMPY\x01\x00", 8);
  bytes.push_back(static_cast<char>(header.size() & 0xff));
  bytes.push_back(static_cast<char>(header.size() >> 8));
  bytes += header;
  const size_t at = bytes.size();
  bytes.resize(at + 4 * m.values.size());
  if (!m.values.empty()) std::memcpy(bytes.data() + at, m.values.data(), 4 * m.values.size());
  return WriteFileAtomically(path, bytes);
}

}  // namespace ratslam::dataset
