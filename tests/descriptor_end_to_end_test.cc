// The descriptor front end end to end, as a user with descriptors from their own network would
// run it: `ratslam replay` on a data set whose images are gone, with descriptors.npy beside it.
// The descriptors here are an oracle of known similarity: random Fourier features of the true
// position, whose cosine similarity approximates exp(-d^2 / (2 l^2)) for places d apart. So the
// matches must be true re-visits, the map must beat odometry, and a second session must
// localise on the saved map.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/random.h"
#include "dataset/descriptor_file.h"
#include "dataset/synthetic_dataset.h"
#include "tests/run_ratslam.h"
#include "tests/test_paths.h"

namespace ratslam {
namespace {
namespace fs = std::filesystem;
using e2e::RunRatslam;
using e2e::Slurp;

constexpr int kDimensions = 256;
constexpr double kLengthScaleM = 1.0;

// One descriptor per image from the true position at its time, plus noise.
dataset::DescriptorMatrix OracleDescriptors(const dataset::Dataset& d, uint64_t noise_seed) {
  Random features(7);  // the same features for every session: one descriptor "network"
  std::vector<double> wx(kDimensions), wy(kDimensions), phase(kDimensions);
  for (int k = 0; k < kDimensions; ++k) {
    wx[k] = features.Gaussian() / kLengthScaleM;
    wy[k] = features.Gaussian() / kLengthScaleM;
    phase[k] = features.Uniform(0.0, 2.0 * M_PI);
  }
  Random noise(noise_seed);
  dataset::DescriptorMatrix m;
  m.rows = d.images.size();
  m.cols = kDimensions;
  for (const ImageRow& image : d.images) {
    const std::optional<GroundTruthRow> p =
        dataset::InterpolateGroundTruth(d.ground_truth, image.time_s);
    const double x = p ? p->x_m : 0.0, y = p ? p->y_m : 0.0;
    for (int k = 0; k < kDimensions; ++k) {
      m.values.push_back(
          static_cast<float>(std::cos(wx[k] * x + wy[k] * y + phase[k]) + 0.05 * noise.Gaussian()));
    }
  }
  return m;
}

class DescriptorEndToEndTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("ratslam_descriptors_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    for (int session = 0; session < 2; ++session) {
      dataset::SyntheticOptions o;
      o.laps = session == 0 ? 2 : 1;
      o.noise_seed = 11 + session;
      o.start_m = session == 0 ? 0.0 : 30.0;
      const fs::path folder = root_ / ("session" + std::to_string(session));
      StatusOr<dataset::Dataset> d = dataset::WriteSyntheticDataset(o, folder.string());
      ASSERT_TRUE(d.ok()) << d.status().message();
      // The descriptors were computed elsewhere; the images are not needed any more.
      fs::remove_all(folder / "images");
      ASSERT_TRUE(dataset::WriteDescriptorNpy(OracleDescriptors(*d, 100 + session),
                                              (folder / "descriptors.npy").string())
                      .ok());
    }
    std::string toml =
        Slurp(fs::path(ratslam::test_paths::SourceDir()) / "configs" / "synthetic.toml");
    const std::string from = "kind = \"classic_camera\"";
    toml.replace(toml.find(from), from.size(), "kind = \"descriptors\"");
    ASSERT_EQ(toml.find("[descriptors]"), std::string::npos);
    // Matches within about 0.4 m: exp(-0.4^2 / 2) = 0.92.
    toml += "\n[descriptors]\nmin_similarity = 0.92\n";
    config_ = (root_ / "descriptors.toml").string();
    std::ofstream(config_) << toml;
    std::ofstream(root_ / "absent.toml") << toml << "file = \"absent.npy\"\n";
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static std::string Replay(const std::string& session, const std::string& out,
                            const std::string& extra = "") {
    return "replay --quiet --config " + config_ + " --data " + (root_ / session).string() +
           " --out " + (root_ / out).string() + extra;
  }
  static nlohmann::json Summary(const std::string& out) {
    return nlohmann::json::parse(Slurp(root_ / out / "summary.json"));
  }
  static fs::path root_;
  static std::string config_;
};
fs::path DescriptorEndToEndTest::root_;
std::string DescriptorEndToEndTest::config_;

TEST_F(DescriptorEndToEndTest, MatchesAreTrueRevisitsAndTheMapBeatsOdometry) {
  const e2e::Result r =
      RunRatslam(Replay("session0", "map", " --save-map " + (root_ / "map.map").string()), root_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json s = Summary("map");
  EXPECT_EQ(s["images_unused"].get<int>(), 0);
  EXPECT_EQ(s["frames"].get<int>(),
            s["frames_by_source"]["camera"].get<int>() + s["frames_by_source"]["new"].get<int>());
  EXPECT_GT(s["loop_closures"].get<int>(), 10);
  EXPECT_GT(s["matches"].get<int>(), 100);
  // The oracle matches only places within about half a metre.
  EXPECT_GE(s["match_rate_within_m"]["2"].get<double>(), 0.99);
  const double map_ate = s["map_ate_m"], odometry_ate = s["odometry_ate_m"];
  EXPECT_LT(map_ate, 0.3 * odometry_ate) << "map " << map_ate << " odometry " << odometry_ate;
}

TEST_F(DescriptorEndToEndTest, AnotherSessionLocalisesOnTheSavedMap) {
  if (!fs::exists(root_ / "map.map")) {
    ASSERT_EQ(
        RunRatslam(Replay("session0", "map2", " --save-map " + (root_ / "map.map").string()), root_)
            .exit_code,
        0);
  }
  const e2e::Result r = RunRatslam(
      Replay("session1", "localise", " --localise --load-map " + (root_ / "map.map").string()),
      root_);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json l = Summary("localise")["localisation"];
  EXPECT_LT(l["lost_fraction"].get<double>(), 0.2) << l.dump();
  EXPECT_LT(l["median_error_m"].get<double>(), 1.0) << l.dump();
}

TEST_F(DescriptorEndToEndTest, MissingOrMiscountedDescriptorsNameTheFile) {
  const fs::path folder = root_ / "session1";
  fs::copy_file(folder / "descriptors.npy", root_ / "saved.npy",
                fs::copy_options::overwrite_existing);
  dataset::DescriptorMatrix three{3, kDimensions, std::vector<float>(3 * kDimensions, 1.0f)};
  ASSERT_TRUE(dataset::WriteDescriptorNpy(three, (folder / "descriptors.npy").string()).ok());
  const e2e::Result miscounted = RunRatslam(Replay("session1", "bad1"), root_);
  fs::copy_file(root_ / "saved.npy", folder / "descriptors.npy",
                fs::copy_options::overwrite_existing);
  EXPECT_EQ(miscounted.exit_code, 1);
  EXPECT_NE(miscounted.err.find("descriptors.npy: 3 descriptors, but the data set has"),
            std::string::npos)
      << miscounted.err;
  const e2e::Result absent =
      RunRatslam("replay --quiet --config " + (root_ / "absent.toml").string() + " --data " +
                     folder.string() + " --out " + (root_ / "bad2").string(),
                 root_);
  EXPECT_EQ(absent.exit_code, 1);
  EXPECT_NE(absent.err.find((folder / "absent.npy").string()), std::string::npos) << absent.err;
}

}  // namespace
}  // namespace ratslam
