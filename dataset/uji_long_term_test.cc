#include "dataset/uji_long_term.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/scratch_dir.h"

namespace ratslam::dataset {
namespace {

namespace fs = std::filesystem;

const ScratchDir& TestScratch() {
  static const ScratchDir dir("ratslam_test");
  return dir;
}

// Writes the set `name` (e.g. "db/01/trn01") with the given file contents; an empty string
// leaves that file out.
std::string WriteSet(const std::string& name, const std::string& rss, const std::string& crd,
                     const std::string& tms = "", const std::string& ids = "") {
  const fs::path stem = TestScratch().path() / name;
  fs::create_directories(stem.parent_path());
  const std::pair<const char*, const std::string*> files[] = {
      {"rss.csv", &rss}, {"crd.csv", &crd}, {"tms.csv", &tms}, {"ids.csv", &ids}};
  for (const auto& [suffix, text] : files) {
    const fs::path p = stem.string() + suffix;
    fs::remove(p);
    if (!text->empty()) std::ofstream(p) << *text;
  }
  return stem.string() + "rss.csv";
}

const char kRss[] = "100,-71,100,-45\n-80,100,-60.5,100\n100,100,-90,-91\n";
const char kCrd[] = "1.5,2.25,3\n10,-4,3\n7.5,8,5\n";

TEST(UjiLongTermTest, ReadsAKnownSet) {
  // Times in three of the accepted forms; the oracle is Unix time from Python's
  // calendar.timegm: 2016-01-01 00:00:00 = 1451606400 (MATLAB date number 736330),
  // 2016-06-21 12:30:15 = 1466512215, 2017-02-28 23:59:59 = 1488326399.
  const std::string path = WriteSet(
      "db/01/trn01", kRss, kCrd, "736330\n2016-06-21 12:30:15\n2017,2,28,23,59,59\n", "7\n8\n9\n");
  UjiLongTermReport report;
  auto scans = ReadUjiLongTermSet(path, false, &report);
  ASSERT_TRUE(scans.ok()) << scans.status().message();
  ASSERT_EQ(scans->size(), 3u);
  EXPECT_EQ(report.rows, 3u);
  EXPECT_EQ(report.access_points, 4u);
  EXPECT_TRUE(report.has_times && report.has_ids);
  const LabelledScan& a = (*scans)[0];
  ASSERT_EQ(a.readings.size(), 2u);
  EXPECT_EQ(a.readings[0].bssid, "AP002");
  EXPECT_EQ(a.readings[0].rssi_dbm, -71);
  EXPECT_EQ(a.readings[1].bssid, "AP004");
  EXPECT_EQ(a.readings[1].rssi_dbm, -45);
  EXPECT_EQ(a.x_m, 1.5);
  EXPECT_EQ(a.y_m, 2.25);
  EXPECT_EQ(a.floor, 3);
  EXPECT_EQ(a.space, 7);
  EXPECT_EQ(a.time_s, 1451606400.0);
  EXPECT_EQ((*scans)[1].time_s, 1466512215.0);
  EXPECT_EQ((*scans)[1].readings[1].rssi_dbm, -60.5);
  EXPECT_EQ((*scans)[2].time_s, 1488326399.0);
  EXPECT_EQ((*scans)[2].floor, 5);
  EXPECT_EQ((*scans)[2].line, 3);
}

TEST(UjiLongTermTest, AnyFileOfTheSetFindsTheOthers) {
  const std::string rss = WriteSet("db/02/tst03", kRss, kCrd);
  const std::string stem = rss.substr(0, rss.size() - 7);
  for (const char* suffix : {"rss.csv", "crd.csv"}) {
    auto files = FindUjiLongTermFiles(stem + suffix);
    ASSERT_TRUE(files.ok()) << files.status().message();
    EXPECT_EQ(files->rss, stem + "rss.csv");
    EXPECT_EQ(files->crd, stem + "crd.csv");
    EXPECT_TRUE(files->tms.empty() && files->ids.empty());
  }
  EXPECT_TRUE(IsUjiLongTermSet(rss));
  // Without times the row number is the time.
  auto scans = ReadUjiLongTermSet(rss);
  ASSERT_TRUE(scans.ok()) << scans.status().message();
  EXPECT_EQ((*scans)[2].time_s, 2.0);
  // A UJIIndoorLoc-style name is not a set; a set without coordinates is an error naming them.
  EXPECT_FALSE(IsUjiLongTermSet(stem + "whatever.csv"));
  fs::remove(stem + "crd.csv");
  EXPECT_FALSE(IsUjiLongTermSet(rss));
  auto missing = ReadUjiLongTermSet(rss);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find(stem + "crd.csv"), std::string::npos);
}

// Each bad input is an error naming the file, the line and the field.
TEST(UjiLongTermTest, BadInputNamesFileLineAndField) {
  struct Case {
    std::string rss, crd, tms, ids;
    std::string file, where;  // suffix of the file the error names; "line: field" text
  };
  const std::string crd3 = "1,2,3\n4,5,3\n";
  const Case cases[] = {
      {"100,-71\n100,nan\n", crd3, "", "", "rss.csv", ":2: field 'AP002': not a number"},
      {"100,-71\n100,5\n", crd3, "", "", "rss.csv", ":2: field 'AP002': RSSI out of range"},
      {"100,-71\n100\n", crd3, "", "", "rss.csv", ":2: expected 2 fields"},
      {"WAP001,WAP002\n100,-71\n", crd3, "", "", "rss.csv", ":1: field 'AP001': not a number"},
      {"100,-71\n100,-60\n", "1,2,3\n4,5\n", "", "", "crd.csv", ":2: expected 3 fields"},
      {"100,-71\n100,-60\n", "1,2,3\n4,5,3.5\n", "", "", "crd.csv", ":2: field 'floor'"},
      {"100,-71\n100,-60\n", "1,2,3\n4,inf,3\n", "", "", "crd.csv", ":2: field 'y'"},
      {"100,-71\n100,-60\n", "1,2,3\n", "", "", "crd.csv", "1 rows, but"},
      {"100,-71\n100,-60\n", crd3, "1\nyesterday\n", "", "tms.csv", ":2: field 'time'"},
      {"100,-71\n100,-60\n", crd3, "1\n2016-13-01 00:00:00\n", "", "tms.csv", ":2: field 'time'"},
      {"100,-71\n100,-60\n", crd3, "1\n2016,2,30,0,0,0\n", "", "tms.csv", ":2: field 'time'"},
      {"100,-71\n100,-60\n", crd3, "1\n-5\n", "", "tms.csv", ":2: field 'time': out of range"},
      {"100,-71\n100,-60\n", crd3, "1\n1969-12-31 23:59:59\n", "", "tms.csv", ":2: field 'time'"},
      {"100,-71\n100,-60\n", crd3, "1\n1,2\n", "", "tms.csv", ":2: expected 1 field"},
      {"100,-71\n100,-60\n", crd3, "", "1\n2.5\n", "ids.csv", ":2: field 'id 1'"},
  };
  for (const Case& c : cases) {
    const std::string path = WriteSet("bad/trn01", c.rss, c.crd, c.tms, c.ids);
    auto scans = ReadUjiLongTermSet(path);
    ASSERT_FALSE(scans.ok()) << c.where;
    const std::string message = scans.status().message();
    const std::string file = path.substr(0, path.size() - 7) + c.file;
    EXPECT_EQ(message.rfind(file, 0), 0u) << message;
    EXPECT_NE(message.find(c.where), std::string::npos) << message;
  }
  // An empty RSS file.
  const std::string empty = WriteSet("bad/trn02", " \n", "1,2,3\n");
  EXPECT_FALSE(ReadUjiLongTermSet(empty).ok());
}

// A fuzzer finding (fuzz/regressions/uji_long_term_fuzzer/datenum-before-1970-negative-time):
// 706330 was read as a MATLAB date number of 1933, a negative time. Date numbers now start at
// 1970-01-01 (719529); below that a number is seconds.
// The published files hold 17-digit times yyyymmddHHMMSSfff; 14 digits drop the milliseconds.
// Oracle: Python's calendar.timegm: 2016-06-02 15:52:17 = 1464882737, 2017-01-31 09:05:00 =
// 1485853500. Digits that are no date are an error naming the form.
TEST(UjiLongTermTest, ReadsThePublishedSeventeenDigitTimes) {
  const std::string path = WriteSet("published/trn01", "100,-71\n100,-60\n", "1,2,3\n4,5,3\n",
                                    "20160602155217232\n20170131090500\n");
  auto scans = ReadUjiLongTermSet(path);
  ASSERT_TRUE(scans.ok()) << scans.status().message();
  EXPECT_DOUBLE_EQ((*scans)[0].time_s, 1464882737.232);
  EXPECT_EQ((*scans)[1].time_s, 1485853500.0);
  const std::string bad = WriteSet("published_bad/trn01", "100,-71\n100,-60\n", "1,2,3\n4,5,3\n",
                                   "20160602155217232\n20161302155217232\n");
  auto refused = ReadUjiLongTermSet(bad);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("tms.csv:2: field 'time'"), std::string::npos)
      << refused.status().message();
  EXPECT_NE(refused.status().message().find("yyyymmddHHMMSSfff"), std::string::npos);
}

TEST(UjiLongTermTest, NoTimeBeforeTheEpoch) {
  const std::string path =
      WriteSet("epoch/trn01", "100,-71\n100,-60\n", "1,2,3\n4,5,3\n", "706330\n719529\n");
  auto scans = ReadUjiLongTermSet(path);
  ASSERT_TRUE(scans.ok()) << scans.status().message();
  EXPECT_EQ((*scans)[0].time_s, 706330.0);
  EXPECT_EQ((*scans)[1].time_s, 0.0);
}

TEST(UjiLongTermTest, LenientSkipsBadRowsAndKeepsTheOthersAligned) {
  const std::string path = WriteSet("lenient/tst01", "100,-71\n100,abc\n-50,100\n",
                                    "1,1,3\n2,2,3\n3,3,5\n", "10\n20\n30\n");
  UjiLongTermReport report;
  auto scans = ReadUjiLongTermSet(path, true, &report);
  ASSERT_TRUE(scans.ok()) << scans.status().message();
  ASSERT_EQ(scans->size(), 2u);
  EXPECT_EQ(report.skipped_malformed, 1u);
  EXPECT_EQ((*scans)[1].x_m, 3.0);  // the third row keeps its own coordinates and time
  EXPECT_EQ((*scans)[1].floor, 5);
  EXPECT_EQ((*scans)[1].time_s, 30.0);
  EXPECT_EQ((*scans)[1].readings[0].bssid, "AP001");
  // Files of different lengths cannot be aligned: an error even when lenient.
  const std::string short_crd = WriteSet("lenient/tst02", "100,-71\n100,-60\n", "1,1,3\n");
  EXPECT_FALSE(ReadUjiLongTermSet(short_crd, true).ok());
}

}  // namespace
}  // namespace ratslam::dataset
