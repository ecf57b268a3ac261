#include "dataset/descriptor_file.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>

#include "common/scratch_dir.h"

namespace ratslam::dataset {
namespace {

// A .npy written by hand from NumPy's format description: magic, version, header length, the
// header dict, then the data.
std::string Npy(const std::string& header, const std::string& data, int version = 1) {
  std::string bytes = "\x93NUMPY";
  bytes.push_back(static_cast<char>(version));
  bytes.push_back('\0');
  const size_t n = header.size();
  bytes.push_back(static_cast<char>(n & 0xff));
  bytes.push_back(static_cast<char>((n >> 8) & 0xff));
  if (version > 1) bytes.append(2, '\0');
  return bytes + header + data;
}

template <typename T>
std::string Raw(const std::vector<T>& values) {
  std::string s(values.size() * sizeof(T), '\0');
  std::memcpy(s.data(), values.data(), s.size());
  return s;
}

TEST(DescriptorFileTest, ReadsFloat32COrder) {
  const auto m =
      ParseDescriptors(Npy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }\n",
                           Raw<float>({1, 2, 3, 4, 5, 6})),
                       "a.npy", true);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->rows, 2u);
  EXPECT_EQ(m->cols, 3u);
  EXPECT_EQ(m->values, (std::vector<float>{1, 2, 3, 4, 5, 6}));
}

// Fortran order stores columns one after another: the same matrix from transposed bytes.
TEST(DescriptorFileTest, ReadsFloat64FortranOrderVersion2) {
  const auto m =
      ParseDescriptors(Npy("{\"descr\": \"<f8\", \"fortran_order\": True, \"shape\": (2, 3)}",
                           Raw<double>({1, 4, 2, 5, 3, 6}), 2),
                       "b.npy", true);
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->values, (std::vector<float>{1, 2, 3, 4, 5, 6}));
}

TEST(DescriptorFileTest, WrittenNpyReadsBackAndIsAligned) {
  ScratchDir dir("ratslam_descriptors");
  DescriptorMatrix m{3, 2, {0.5f, -1.25f, 3e-8f, 7.0f, -0.0f, 1e30f}};
  const std::string path = (dir.path() / "d.npy").string();
  ASSERT_TRUE(WriteDescriptorNpy(m, path).ok());
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // NumPy pads the header so that the data starts on a 64-byte boundary.
  const size_t header_len =
      static_cast<unsigned char>(bytes[8]) | static_cast<unsigned char>(bytes[9]) << 8;
  EXPECT_EQ((10 + header_len) % 64, 0u);
  const auto back = ReadDescriptorFile(path);
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->rows, 3u);
  EXPECT_EQ(back->cols, 2u);
  EXPECT_EQ(std::memcmp(back->values.data(), m.values.data(), 6 * sizeof(float)), 0);
}

TEST(DescriptorFileTest, ReadsCsvWithAndWithoutHeader) {
  const auto a = ParseDescriptors("d0,d1\n1, 2.5\n-3,4e2\r\n", "a.csv", false);
  ASSERT_TRUE(a.ok()) << a.status().message();
  EXPECT_EQ(a->rows, 2u);
  EXPECT_EQ(a->values, (std::vector<float>{1, 2.5f, -3, 400}));
  const auto b = ParseDescriptors("1,2\n3,4", "b.csv", false);
  ASSERT_TRUE(b.ok()) << b.status().message();
  EXPECT_EQ(b->rows, 2u);
  EXPECT_EQ(b->values, (std::vector<float>{1, 2, 3, 4}));
}

void ExpectError(const std::string& bytes, bool npy, const std::string& fragment) {
  const auto m = ParseDescriptors(bytes, npy ? "x.npy" : "x.csv", npy);
  ASSERT_FALSE(m.ok()) << "accepted; expected: " << fragment;
  EXPECT_NE(m.status().message().find(fragment), std::string::npos) << m.status().message();
}

TEST(DescriptorFileTest, BadNpyIsAnErrorNamingWhatIsWrong) {
  const std::string h = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 2), }";
  const std::string four = Raw<float>({1, 2, 3, 4});
  ExpectError("PK\x03\x04 not npy at all", true, "no \\x93NUMPY magic");
  ExpectError(Npy(h, four).substr(0, 30), true, "truncated .npy header");
  ExpectError(Npy(h, four.substr(0, 12)), true, "truncated or padded");
  ExpectError(Npy(h, four + "x"), true, "truncated or padded");
  ExpectError(Npy("{'descr': '<i4', 'fortran_order': False, 'shape': (2, 2), }", four), true,
              "dtype '<i4'");
  ExpectError(Npy("{'descr': '>f4', 'fortran_order': False, 'shape': (2, 2), }", four), true,
              "dtype '>f4'");
  ExpectError(Npy("{'descr': '<f4', 'fortran_order': False, 'shape': (4,), }", four), true,
              "1 dimensions");
  ExpectError(Npy("{'descr': '<f4', 'fortran_order': False, 'shape': (0, 2), }", ""), true,
              "zero rows");
  ExpectError(Npy("{'descr': '<f4', 'fortran_order': 0, 'shape': (2, 2), }", four), true,
              "neither True nor False");
  ExpectError(Npy("{'descr': '<f4', 'shape': (2, 2), }", four), true, "needs 'descr'");
  ExpectError(
      Npy("{'descr': '<f4', 'descr': '<f4', 'fortran_order': False, 'shape': (2, 2)}", four), true,
      "repeated key 'descr'");
  // A shape claiming far more data than the file holds fails before any allocation.
  ExpectError(
      Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999, 99999999999), }", four),
      true, "truncated or padded");
  ExpectError(Npy(h, Raw<float>({1, 2, std::nanf(""), 4})), true, "row 1, column 0: not finite");
  ExpectError(
      Npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 2), }", Raw<double>({1.0, 1e300})),
      true, "row 0, column 1: out of float range");
}

TEST(DescriptorFileTest, BadCsvIsAnErrorNamingLineAndColumn) {
  ExpectError("", false, "no data line");
  ExpectError("a,b\n", false, "no data line");
  ExpectError("1,2\n3\n", false, "x.csv:2: 1 fields, expected 2");
  ExpectError("1,2\n\n3,4\n", false, "x.csv:2: empty line");
  ExpectError("1,2\n3,four\n", false, "x.csv:2: column 2: not a number: 'four'");
  ExpectError("1,nan\n", false, "x.csv:1: column 2: not finite");
  ExpectError("1,2\n3,1e39\n", false, "x.csv:2: column 2: out of float range");
}

TEST(DescriptorFileTest, MissingFileAndFolderAreErrors) {
  ScratchDir dir("ratslam_descriptors");
  EXPECT_FALSE(ReadDescriptorFile((dir.path() / "absent.npy").string()).ok());
  const auto folder = ReadDescriptorFile(dir.path().string());
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.status().message().find("not a regular file"), std::string::npos);
}

}  // namespace
}  // namespace ratslam::dataset
