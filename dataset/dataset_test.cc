#include "dataset/dataset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "dataset/dataset_loader.h"
#include "dataset/image_loader.h"
#include "dataset/synthetic_dataset.h"
#include "dataset/visual_odometry_source.h"

namespace ratslam::dataset {
namespace {
namespace fs = std::filesystem;

class DatasetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() /
              ("ratslam_dataset_test_" + std::to_string(::getpid()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(folder_);
    fs::create_directories(folder_);
    Write("manifest.toml",
          "format = \"ratslam-replay\"\nformat_version = 1\nname = \"t\"\n[streams]\n"
          "odometry = \"odometry.csv\"\nground_truth = \"ground_truth.csv\"\n"
          "wifi = \"wifi.csv\"\n");
    Write("odometry.csv", "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n0,0,0\n0.1,1,0.5\n");
    Write("ground_truth.csv", "time_s,x_m,y_m\n0,0,0\n1,10,-4\n");
    Write("wifi.csv", "time_s,bssid,rssi_dbm\n0.5,aa:bb,-40\n0.5,cc:dd,-71\n0.9,aa:bb,-45\n");
  }
  void TearDown() override { fs::remove_all(folder_); }
  void Write(const std::string& name, const std::string& text) {
    std::ofstream(folder_ / name) << text;
  }
  std::string ReadError() {
    StatusOr<Dataset> d = ReadDataset(folder_.string());
    EXPECT_FALSE(d.ok());
    return d.status().message();
  }
  fs::path folder_;
};

TEST_F(DatasetTest, ReadsValidFolder) {
  StatusOr<Dataset> d = ReadDataset(folder_.string());
  ASSERT_TRUE(d.ok()) << d.status().message();
  ASSERT_EQ(d->odometry.size(), 2u);
  EXPECT_EQ(d->odometry[1].turn_rate_rad_per_s, 0.5);
  ASSERT_EQ(d->wifi.size(), 2u);  // readings at equal times form one scan
  EXPECT_EQ(d->wifi[0].readings.size(), 2u);
  EXPECT_EQ(d->wifi[0].readings[1].rssi_dbm, -71);
}

TEST_F(DatasetTest, WriteThenReadIsExact) {
  Dataset d = ReadDataset(folder_.string()).value();
  d.odometry[1].forward_speed_m_per_s = 0.1 + 0.2;  // not representable in short decimal
  d.compass.push_back({0.3, -2.5});
  const fs::path copy = folder_ / "copy";
  ASSERT_TRUE(WriteDataset(d, copy.string()).ok());
  Dataset back = ReadDataset(copy.string()).value();
  EXPECT_EQ(back.odometry[1].forward_speed_m_per_s, 0.1 + 0.2);
  EXPECT_EQ(back.compass.size(), 1u);
  EXPECT_EQ(back.ground_truth[1].y_m, -4);
  EXPECT_EQ(back.wifi[0].readings[0].bssid, "aa:bb");
}

// A folder that joined several sessions (ratslam import of several logs) is still several
// sessions when replayed alone: its session starts survive LoadSessions. A folder without them
// is one session from its first odometry row.
TEST_F(DatasetTest, LoadSessionsKeepsAJoinedFoldersSessions) {
  Write("manifest.toml",
        "format = \"ratslam-replay\"\nformat_version = 1\nname = \"t\"\n"
        "session_start_times_s = [0.0, 0.4, 0.8]\n[streams]\nodometry = \"odometry.csv\"\n");
  StatusOr<Dataset> joined = LoadSessions({folder_.string()}, {});
  ASSERT_TRUE(joined.ok()) << joined.status().message();
  EXPECT_EQ(joined->session_start_times_s, (std::vector<double>{0.0, 0.4, 0.8}));
  Write("manifest.toml",
        "format = \"ratslam-replay\"\nformat_version = 1\nname = \"t\"\n[streams]\n"
        "odometry = \"odometry.csv\"\n");
  Write("odometry.csv", "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n0.25,0,0\n0.5,1,0\n");
  StatusOr<Dataset> single = LoadSessions({folder_.string()}, {});
  ASSERT_TRUE(single.ok()) << single.status().message();
  EXPECT_EQ(single->session_start_times_s, (std::vector<double>{0.25}));
}

// Sessions keep their names: a joined folder's from its manifest (written and read back), joined
// files' from the files, two of one name told apart by their order; a manifest whose names do
// not match its sessions names the key.
TEST_F(DatasetTest, SessionNamesRoundTripAndComeFromTheJoinedFiles) {
  Dataset d = ReadDataset(folder_.string()).value();
  d.session_start_times_s = {0.0, 0.05};
  d.session_names = {"summer \"day\"", "winter"};
  const fs::path copy = folder_ / "named";
  ASSERT_TRUE(WriteDataset(d, copy.string()).ok());
  StatusOr<Dataset> back = LoadSessions({copy.string()}, {});
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->session_names, d.session_names);
  EXPECT_EQ(back->SessionName(1), "winter");
  EXPECT_EQ(Dataset{}.SessionName(2), "session 3");

  d.session_names = {"only one"};
  EXPECT_NE(WriteDataset(d, (folder_ / "refused").string()).message().find("1 session names for 2"),
            std::string::npos);
  Write("manifest.toml",
        "format = \"ratslam-replay\"\nformat_version = 1\nname = \"t\"\n"
        "session_start_times_s = [0.0, 0.4]\nsession_names = [\"a\"]\n[streams]\n"
        "odometry = \"odometry.csv\"\n");
  EXPECT_NE(ReadError().find("manifest.toml:5: session_names: 1 names for 2 sessions"),
            std::string::npos)
      << ReadError();

  const fs::path a = folder_ / "a", b = folder_ / "b";
  Dataset one = ReadDataset(copy.string()).value();
  one.session_start_times_s.clear();
  one.session_names.clear();
  one.name = "morning";
  ASSERT_TRUE(WriteDataset(one, a.string()).ok());
  one.name = "evening";
  ASSERT_TRUE(WriteDataset(one, b.string()).ok());
  StatusOr<Dataset> joined = LoadSessions({a.string(), b.string(), a.string()}, {});
  ASSERT_TRUE(joined.ok()) << joined.status().message();
  EXPECT_EQ(joined->session_names,
            (std::vector<std::string>{"morning (1)", "evening", "morning (2)"}));
}

TEST_F(DatasetTest, TruncatedRowNamesFileAndLine) {
  Write("odometry.csv", "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n0,0,0\n0.1,1\n");
  const std::string error = ReadError();
  EXPECT_NE(error.find("odometry.csv:3"), std::string::npos) << error;
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;
}

TEST_F(DatasetTest, NanNamesColumn) {
  Write("odometry.csv", "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n0,nan,0\n");
  const std::string error = ReadError();
  EXPECT_NE(error.find("odometry.csv:2: column 'forward_speed_m_per_s'"), std::string::npos)
      << error;
}

TEST_F(DatasetTest, NotANumberNamesColumn) {
  Write("ground_truth.csv", "time_s,x_m,y_m\n0,0,0\n1,ten,0\n");
  const std::string error = ReadError();
  EXPECT_NE(error.find("ground_truth.csv:3: column 'x_m': not a number: 'ten'"), std::string::npos)
      << error;
}

TEST_F(DatasetTest, TimeGoingBackwardsIsAnError) {
  Write("odometry.csv", "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n1,0,0\n0.5,0,0\n");
  const std::string error = ReadError();
  EXPECT_NE(error.find("odometry.csv:3: column 'time_s': time goes backwards"), std::string::npos)
      << error;
}

TEST_F(DatasetTest, MissingAndUnknownColumns) {
  Write("odometry.csv", "time_s,forward_speed_m_per_s\n0,0\n");
  EXPECT_NE(ReadError().find("missing required column 'turn_rate_rad_per_s'"), std::string::npos);
  Write("odometry.csv", "time_s,forward_speed_m_per_s,turn_rate_rad_per_sec\n0,0,0\n");
  EXPECT_NE(ReadError().find("unknown column 'turn_rate_rad_per_sec'"), std::string::npos);
}

TEST_F(DatasetTest, MissingStreamFileAndUnknownManifestKey) {
  fs::remove(folder_ / "wifi.csv");
  EXPECT_NE(ReadError().find("wifi.csv: cannot open file"), std::string::npos);
  Write("manifest.toml",
        "format = \"ratslam-replay\"\nformat_version = 1\n[streams]\nodometry = \"odometry.csv\"\n"
        "odometer = \"x.csv\"\n");
  const std::string error = ReadError();
  EXPECT_NE(
      error.find("manifest.toml:5: unknown key 'odometer' in [streams] (did you mean 'odometry'?)"),
      std::string::npos)
      << error;
}

// The manifest goes through the same binder as configs and worlds: every error names the line and
// the key, in the same words.
TEST_F(DatasetTest, ManifestErrorsNameLineAndKey) {
  const std::string head = "format = \"ratslam-replay\"\nformat_version = 1\n";
  const std::string streams = "[streams]\nodometry = \"odometry.csv\"\n";
  Write("manifest.toml", head + "session_start_times_s = [0.0, 10.0, 5.0]\n" + streams);
  EXPECT_NE(ReadError().find("manifest.toml:3: session_start_times_s: must be increasing"),
            std::string::npos)
      << ReadError();
  Write("manifest.toml", head + "session_start_times_s = [-1.0]\n" + streams);
  EXPECT_NE(ReadError().find("manifest.toml:3: session_start_times_s: element 0: must be zero or "
                             "more"),
            std::string::npos)
      << ReadError();
  Write("manifest.toml", head + "name = 3\n" + streams);
  EXPECT_NE(ReadError().find("manifest.toml:3: name: expected a string"), std::string::npos)
      << ReadError();
  Write("manifest.toml", "format = \"ratslam-replay\"\nformat_version = 2\n" + streams);
  EXPECT_NE(ReadError().find("manifest.toml:2: unsupported format_version"), std::string::npos)
      << ReadError();
  Write("manifest.toml", head + "[streams]\nwifi = \"wifi.csv\"\n");
  EXPECT_NE(ReadError().find("manifest.toml:3: streams.odometry is required (or streams.images"),
            std::string::npos)
      << ReadError();
}

// A manifest is untrusted: streams must be regular files inside the data-set folder. These once
// grew without end (/dev/zero) or read another file and echoed its first line.
TEST_F(DatasetTest, StreamsOutsideTheFolderOrNotRegularFilesAreRefused) {
  const std::string head =
      "format = \"ratslam-replay\"\nformat_version = 1\n[streams]\nodometry = ";
  Write("manifest.toml", head + "\"/dev/zero\"\n");
  EXPECT_NE(ReadError().find("streams.odometry: must be a relative path inside the folder"),
            std::string::npos);
  Write("manifest.toml", head + "\"../../etc/passwd\"\n");
  const std::string escape = ReadError();
  EXPECT_NE(escape.find("manifest.toml:4: streams.odometry: must be a relative path"),
            std::string::npos)
      << escape;
  EXPECT_EQ(escape.find("root"), std::string::npos) << escape;
  fs::create_symlink("/dev/zero", folder_ / "zero.csv");
  Write("manifest.toml", head + "\"zero.csv\"\n");
  EXPECT_NE(ReadError().find("zero.csv: file is not a regular file"), std::string::npos);
  fs::create_directory(folder_ / "folder.csv");
  Write("manifest.toml", head + "\"folder.csv\"\n");
  EXPECT_NE(ReadError().find("not a regular file"), std::string::npos);
}

TEST_F(DatasetTest, OverlongLinesHugeNumbersAndNegativeTimesAreRefused) {
  Write("odometry.csv", "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n0,0," +
                            std::string(2 << 20, '1') + "\n");
  EXPECT_NE(ReadError().find("odometry.csv:2: line longer than"), std::string::npos);
  Write("odometry.csv", "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n0,1e300,0\n");
  EXPECT_NE(ReadError().find("odometry.csv:2: column 'forward_speed_m_per_s': out of range"),
            std::string::npos);
  Write("odometry.csv", "time_s,forward_speed_m_per_s,turn_rate_rad_per_s\n-1,0,0\n");
  EXPECT_NE(ReadError().find("odometry.csv:2: column 'time_s': must not be negative"),
            std::string::npos);
}

// Whatever WriteDataset writes reads back: names with quotes, backslashes and control characters
// are escaped; a BSSID or image name the CSV cannot hold, or a non-finite number, is an error
// before any file is written.
TEST_F(DatasetTest, HostileNamesRoundTripOrAreRefusedBeforeWriting) {
  Dataset d = ReadDataset(folder_.string()).value();
  d.name = "a \"quoted\" \\ name\twith\x01control";
  d.wifi[0].readings[0].bssid = "ssid with spaces:inside";
  const fs::path copy = folder_ / "copy";
  ASSERT_TRUE(WriteDataset(d, copy.string()).ok());
  StatusOr<Dataset> back = ReadDataset(copy.string());
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->name, d.name);
  EXPECT_EQ(back->wifi[0].readings[0].bssid, d.wifi[0].readings[0].bssid);

  const fs::path refused = folder_ / "refused";
  for (const char* bssid : {"aa,bb", " leading", "line\nbreak", "#comment", ""}) {
    Dataset bad = d;
    bad.wifi[0].readings[0].bssid = bssid;
    const Status status = WriteDataset(bad, refused.string());
    EXPECT_FALSE(status.ok()) << bssid;
    EXPECT_NE(status.message().find("cannot be stored in wifi.csv"), std::string::npos);
  }
  Dataset infinite = d;
  infinite.ground_truth[1].x_m = std::numeric_limits<double>::infinity();
  EXPECT_NE(WriteDataset(infinite, refused.string()).message().find("ground-truth x inf"),
            std::string::npos);
  // An image folder named like one of the written files (found by dataset_fuzzer) could not be
  // both a folder and the file.
  for (const char* folder : {"wifi.csv", "manifest.toml", "odometry.csv/frames"}) {
    Dataset clash = d;
    clash.image_folder = folder;
    const Status status = WriteDataset(clash, refused.string());
    EXPECT_NE(status.message().find("image folder '" + std::string(folder) + "' cannot be stored"),
              std::string::npos)
        << status.message();
  }
  EXPECT_FALSE(fs::exists(refused / "manifest.toml"));
  EXPECT_FALSE(fs::exists(refused / "odometry.csv"));
}

TEST_F(DatasetTest, EventsAreOrderedByTimeThenStream) {
  Dataset d;
  d.odometry = {{0.0, 0, 0}, {0.1, 0, 0}};
  d.images = {{0.1, "a.png", 2}};
  d.compass = {{0.1, 0.0}};
  d.pressure = {{0.1, 1000.0}};
  d.wifi = {{0.1, {{"aa:bb", -50.0}}}};
  const std::vector<Event> events = MergeEvents(d);
  ASSERT_EQ(events.size(), 6u);
  EXPECT_EQ(events[0].type, EventType::kOdometry);
  EXPECT_EQ(events[1].type, EventType::kCompass);
  EXPECT_EQ(events[2].type, EventType::kPressure);
  EXPECT_EQ(events[3].type, EventType::kWifi);
  EXPECT_EQ(events[4].type, EventType::kImage);
  EXPECT_EQ(events[5].type, EventType::kOdometry);
}

TEST_F(DatasetTest, PressureRoundTripsAndBadReadingsNameFileLineAndColumn) {
  Dataset d = ReadDataset(folder_.string()).value();
  d.pressure = {{0.0, 976.8699}, {0.1, 976.8628}, {0.1 + 0.2, 1013.25}};
  const fs::path copy = folder_ / "copy";
  ASSERT_TRUE(WriteDataset(d, copy.string()).ok());
  Dataset back = ReadDataset(copy.string()).value();
  ASSERT_EQ(back.pressure.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.pressure[i].time_s, d.pressure[i].time_s);
    EXPECT_EQ(back.pressure[i].pressure_hpa, d.pressure[i].pressure_hpa);
  }
  d.pressure.push_back({0.5, 5000.0});  // a reader would refuse it: not written
  const Status refused = WriteDataset(d, (folder_ / "refused").string());
  EXPECT_NE(refused.message().find("not writable"), std::string::npos) << refused.message();

  Write("manifest.toml",
        "format = \"ratslam-replay\"\nformat_version = 1\nname = \"t\"\n[streams]\n"
        "odometry = \"odometry.csv\"\npressure = \"pressure.csv\"\n");
  const std::pair<const char*, const char*> bad[] = {
      {"time_s,pressure_hpa\n0,1000\n1,nan\n", "pressure.csv:3: column 'pressure_hpa'"},
      {"time_s,pressure_hpa\n0,1000\n1,50\n", "pressure.csv:3: column 'pressure_hpa': must be"},
      {"time_s,pressure_hpa\n1,1000\n0.5,1000\n", "pressure.csv:3: column 'time_s': time goes"},
      {"time_s,pressure_hpa\n1,1000\n2\n", "pressure.csv:3"},
      {"time_s,hpa\n1,1000\n", "pressure.csv"},
  };
  for (const auto& [text, expected] : bad) {
    Write("pressure.csv", text);
    const std::string error = ReadError();
    EXPECT_NE(error.find(expected), std::string::npos) << error;
  }
}

TEST(GroundTruthTest, FloorIsKnownOnlyWhereThePointsAroundAgree) {
  const std::vector<GroundTruthRow> rows = {
      {0.0, 0, 0, 0, 0}, {10.0, 5, 0, 0, 0}, {20.0, 5, 5, 0, -1}, {30.0, 0, 5, 0, -1}};
  EXPECT_EQ(KnownFloor(rows, 5.0), 0);
  EXPECT_EQ(KnownFloor(rows, 10.0), 0);              // on a point
  EXPECT_FALSE(KnownFloor(rows, 10.5).has_value());  // on the stairs
  EXPECT_FALSE(KnownFloor(rows, 19.9).has_value());
  EXPECT_EQ(KnownFloor(rows, 20.0), -1);
  EXPECT_EQ(KnownFloor(rows, 25.0), -1);
  EXPECT_FALSE(KnownFloor(rows, 31.0).has_value());  // outside the span
  EXPECT_FALSE(KnownFloor({}, 1.0).has_value());
}

TEST(GroundTruthTest, InterpolatesAndRefusesOutsideSpan) {
  std::vector<GroundTruthRow> rows = {{0.0, 0.0, 0.0, 0.0, 0}, {2.0, 4.0, -2.0, 0.0, 0}};
  auto mid = InterpolateGroundTruth(rows, 0.5);
  ASSERT_TRUE(mid.has_value());
  EXPECT_DOUBLE_EQ(mid->x_m, 1.0);
  EXPECT_DOUBLE_EQ(mid->y_m, -0.5);
  EXPECT_FALSE(InterpolateGroundTruth(rows, 2.5).has_value());
}

// Two walks on one clock: the first measured from 10 s to 20 s, the second (starting at 100 s,
// a calibration minute before its first point) from 160 s. Between 20 s and 160 s nobody measured
// where the walker was: no position and no floor, while the plain interpolation (no sessions)
// draws a line from the first walk's end to the second's start.
TEST(GroundTruthTest, NothingIsInterpolatedBetweenTwoSessions) {
  Dataset d;
  d.session_start_times_s = {0.0, 100.0};
  d.ground_truth = {
      {10.0, 0, 0, 0, 0}, {20.0, 10, 0, 0, 0}, {160.0, 0, 0, 0, 0}, {170.0, 0, 10, 0, 0}};
  const auto in_first = GroundTruthAt(d, 15.0);
  ASSERT_TRUE(in_first.has_value());
  EXPECT_DOUBLE_EQ(in_first->x_m, 5.0);
  const auto in_second = GroundTruthAt(d, 165.0);
  ASSERT_TRUE(in_second.has_value());
  EXPECT_DOUBLE_EQ(in_second->y_m, 5.0);
  for (double t : {20.5, 99.0, 100.0, 130.0, 159.9}) {
    EXPECT_FALSE(GroundTruthAt(d, t).has_value()) << t;
    EXPECT_FALSE(KnownFloorAt(d, t).has_value()) << t;
  }
  EXPECT_FALSE(GroundTruthAt(d, 5.0).has_value());  // before the first walk's first point
  // On the points themselves, and within a walk, the floor is known.
  ASSERT_TRUE(GroundTruthAt(d, 20.0).has_value());
  EXPECT_DOUBLE_EQ(GroundTruthAt(d, 20.0)->x_m, 10.0);
  EXPECT_EQ(GroundTruthAt(d, 160.0)->y_m, 0.0);
  EXPECT_EQ(KnownFloorAt(d, 165.0), 0);
  // Without sessions the same rows are one walk: (10, 0) at 20 s to (0, 0) at 160 s.
  const auto joined = InterpolateGroundTruth(d.ground_truth, 90.0);
  ASSERT_TRUE(joined.has_value());
  EXPECT_DOUBLE_EQ(joined->x_m, 5.0);
  // A single session (or none recorded) interpolates everywhere inside the span.
  d.session_start_times_s = {0.0};
  EXPECT_TRUE(GroundTruthAt(d, 90.0).has_value());
  d.session_start_times_s.clear();
  EXPECT_TRUE(GroundTruthAt(d, 90.0).has_value());
}

TEST(SyntheticDatasetTest, SameSeedSameBytesAndImagesRepeatAcrossLaps) {
  SyntheticOptions options;
  options.laps = 2;
  options.loop_length_m = 14;
  options.loop_width_m = 10;
  options.rate_hz = 2;
  options.lap_offset_m = 0.0;
  options.pixel_noise_grey = 0.0;
  const fs::path a = fs::temp_directory_path() / ("ratslam_synth_a_" + std::to_string(::getpid()));
  const fs::path b = fs::temp_directory_path() / ("ratslam_synth_b_" + std::to_string(::getpid()));
  StatusOr<Dataset> da = WriteSyntheticDataset(options, a.string());
  ASSERT_TRUE(da.ok()) << da.status().message();
  ASSERT_TRUE(WriteSyntheticDataset(options, b.string()).ok());
  auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_EQ(bytes(a / "odometry.csv"), bytes(b / "odometry.csv"));
  EXPECT_EQ(bytes(a / "images" / "000003.png"), bytes(b / "images" / "000003.png"));
  // The loop of ~45 m at 1 m/s and 2 Hz: frame k and frame k + one lap see the same place.
  const Dataset& d = da.value();
  const double perimeter = 2 * (14 - 8) + 2 * (10 - 8) + 2 * 3.14159265358979 * 4;
  const size_t lap_frames = static_cast<size_t>(std::lround(perimeter * 2));
  FileImageLoader loader;
  const GrayImage first = loader.Load(d.ImagePath(d.images[1])).value();
  const GrayImage again = loader.Load(d.ImagePath(d.images[1 + lap_frames])).value();
  const GrayImage elsewhere = loader.Load(d.ImagePath(d.images[1 + lap_frames / 2])).value();
  auto mean_difference = [](const GrayImage& x, const GrayImage& y) {
    double sum = 0;
    for (size_t i = 0; i < x.pixels.size(); ++i) sum += std::abs(x.pixels[i] - y.pixels[i]);
    return sum / x.pixels.size();
  };
  EXPECT_LT(mean_difference(first, again), 0.25 * mean_difference(first, elsewhere));
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(ImageLoaderTest, MissingAndCorruptFilesAreErrors) {
  FileImageLoader loader;
  EXPECT_NE(loader.Load("/nonexistent/x.png").status().message().find("image file missing"),
            std::string::npos);
  const fs::path bad =
      fs::temp_directory_path() / ("ratslam_bad_" + std::to_string(::getpid()) + ".png");
  std::ofstream(bad) << "not a png";
  EXPECT_FALSE(loader.Load(bad.string()).ok());
  fs::remove(bad);
}

}  // namespace
}  // namespace ratslam::dataset

namespace ratslam::dataset {
namespace {

// OpenRatSLAM's visual odometry on the synthetic loop, whose camera has a known field of view and
// rate: the integrated turn rate follows the true heading (one turn per lap) and agrees with our
// constant-speed model's rotation (separate code, tested on exact shifts), which an error in the
// sign, the scale or camera_hz would break. Both overestimate the turn by about 17 %: the
// synthetic camera's pixels do not all span field_of_view_rad / width, which both models assume.
TEST(OpenRatslamVisualOdometrySource, TurnsAsTheGroundTruthOnTheSyntheticLoop) {
  SyntheticOptions synthetic;
  synthetic.laps = 1;
  const fs::path folder =
      fs::temp_directory_path() / ("ratslam_vo_loop_" + std::to_string(::getpid()));
  StatusOr<Dataset> d = WriteSyntheticDataset(synthetic, folder.string());
  ASSERT_TRUE(d.ok()) << d.status().message();
  sensors::VisualOdometryOptions vo;
  vo.enabled = true;
  vo.model = "openratslam";
  vo.max_shift_px = 39;
  vo.field_of_view_rad = synthetic.field_of_view_rad;
  vo.camera_hz = synthetic.rate_hz;
  vo.rotation_top_px = 8;
  vo.rotation_bottom_px = 32;
  FileImageLoader images;
  auto turn = [&](const sensors::VisualOdometryOptions& options) {
    Dataset data = d.value();
    EXPECT_TRUE(ReplaceOdometryWithVisual(&data, &images, options).ok());
    EXPECT_EQ(data.odometry.size(), data.images.size());
    double turned = 0.0;
    for (size_t i = 1; i < data.odometry.size(); ++i) {
      turned += data.odometry[i].turn_rate_rad_per_s *
                (data.odometry[i].time_s - data.odometry[i - 1].time_s);
      EXPECT_GE(data.odometry[i].forward_speed_m_per_s, 0.0);
      EXPECT_LE(data.odometry[i].forward_speed_m_per_s, 20.0);
    }
    return turned;
  };
  const double turned = turn(vo);
  sensors::VisualOdometryOptions constant = vo;
  constant.model = "constant_speed";
  constant.crop_top_px = 8;
  constant.crop_bottom_px = 32;
  const double reference = turn(constant);
  double truth = 0.0;
  for (size_t i = 1; i < d->ground_truth.size(); ++i) {
    truth +=
        std::remainder(d->ground_truth[i].theta_rad - d->ground_truth[i - 1].theta_rad, 2 * M_PI);
  }
  EXPECT_NEAR(truth, 2 * M_PI, 0.1);
  EXPECT_NEAR(turned, reference, 0.02 * reference);
  EXPECT_NEAR(turned, truth, 0.25 * truth) << "visual odometry turned " << turned;
  fs::remove_all(folder);
}

}  // namespace
}  // namespace ratslam::dataset
