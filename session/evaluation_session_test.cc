#include "session/evaluation_session.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "common/scratch_dir.h"

namespace ratslam::session {
namespace {

class MemoryFolder : public OutputFolder {
 public:
  std::string Path(const std::string& name) const override { return "mem/" + name; }
  using OutputFolder::Write;
  Status Write(const std::vector<std::pair<std::string, std::string>>& files) override {
    for (const auto& [name, contents] : files) written[name] = contents;
    return Status::Ok();
  }
  std::map<std::string, std::string> written;
};

// Six places 10 m apart on one floor, each heard by its own two access points (and a weak shared
// one), scanned five times: a fingerprint data set in the UJIIndoorLoc layout with a known answer.
// Every query has identical scans of its own place in the map, so FABMAP must localise all of them
// to the right place.
std::string SixPlaces(bool with_malformed_row) {
  std::string csv;
  for (int a = 1; a <= 13; ++a) csv += "WAP" + std::to_string(100 + a) + ",";
  csv += "LONGITUDE,LATITUDE,FLOOR,BUILDINGID,SPACEID,RELATIVEPOSITION,USERID,PHONEID,TIMESTAMP\n";
  int time = 1000;
  for (int scan = 0; scan < 5; ++scan) {
    for (int place = 0; place < 6; ++place) {
      for (int a = 0; a < 13; ++a) {
        const bool own = a == 2 * place || a == 2 * place + 1;
        csv += (own ? "-50" : a == 12 ? "-85" : "100") + std::string(",");
      }
      csv += std::to_string(10 * place) + ",0,0,0,1,2,1,1," + std::to_string(time++) + "\n";
      if (with_malformed_row && scan == 2 && place == 3) csv += "1,2,3\n";
    }
  }
  return csv;
}

EvaluationSessionOptions Options(const std::string& path) {
  EvaluationSessionOptions o;
  o.pipeline.sensors.fabmap.localiser.localiser.mode = fabmap::FabmapMode::kWifi;
  o.map_path = path;
  o.query_path = path;
  return o;
}

TEST(EvaluationSessionTest, KnownPlacesAreAllFoundAndOutputsWritten) {
  ScratchDir dir("ratslam_evaluation");
  const std::string path = (dir / "places.csv").string();
  std::ofstream(path) << SixPlaces(false);
  MemoryFolder out;
  EvaluationSession session(Options(path), &out);
  StatusOr<EvaluationResult> r = session.Run();
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->map.size(), 12u);  // 40 % of 30 rows, interleaved
  EXPECT_EQ(r->queries.size(), 18u);
  EXPECT_EQ(r->metrics.correct_within[0], 1.0);  // within 2 m: every query
  EXPECT_EQ(r->metrics.rejection_rate, 0.0);
  for (size_t i = 0; i < r->queries.size(); ++i) {
    ASSERT_GE(r->matches[i], 0);
    EXPECT_EQ(r->map[r->matches[i]].x_m, r->queries[i].x_m);
  }
  const auto json = nlohmann::json::parse(out.written.at("evaluation.json"));
  EXPECT_EQ(json["queries"], 18);
  EXPECT_EQ(json["correct_within_m"]["2"], 1.0);
  // Fingerprint rows carry no travel: every map scan learns the Wi-Fi tree (it was 1 of 12).
  EXPECT_EQ(json["wifi_map_scans"], 12);
  EXPECT_EQ(json["wifi_tree_scans"], 12);
  EXPECT_TRUE(out.written.count("queries.csv"));
  EXPECT_TRUE(out.written.count("config.toml"));
}

// --lenient reaches the readers (evaluate once ignored it): a malformed row fails the strict run
// naming its line and is skipped by the lenient one.
TEST(EvaluationSessionTest, LenientSkipsMalformedRowsStrictNamesThem) {
  ScratchDir dir("ratslam_evaluation");
  const std::string path = (dir / "places.csv").string();
  std::ofstream(path) << SixPlaces(true);
  MemoryFolder out;
  EvaluationSession strict(Options(path), &out);
  const StatusOr<EvaluationResult> failed = strict.Run();
  ASSERT_FALSE(failed.ok());
  EXPECT_NE(failed.status().message().find("places.csv:18:"), std::string::npos)
      << failed.status().message();
  EvaluationSessionOptions lenient = Options(path);
  lenient.lenient = true;
  EvaluationSession session(lenient, &out);
  const StatusOr<EvaluationResult> r = session.Run();
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->map.size() + r->queries.size(), 30u);
}

}  // namespace
}  // namespace ratslam::session
