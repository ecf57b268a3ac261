#include "session/image_sequence_evaluation.h"

#include <gtest/gtest.h>

namespace ratslam {
namespace {

QueryAnswer Answer(int truth, int reference, double confidence, std::vector<int> top = {}) {
  QueryAnswer a;
  a.truth = truth;
  if (reference < 0) return a;  // declined
  a.match.declined = false;
  a.match.reference = reference;
  a.match.confidence = confidence;
  a.match.candidates.push_back({reference, 0.0});
  for (int t : top) a.match.candidates.push_back({t, 1.0});
  return a;
}

// Five queries by hand, at a tolerance of one frame: by confidence 0.9 right, 0.8 right (one
// frame off), 0.5 wrong (but right in its top five), 0.3 wrong (two frames off); one declined.
// Recall@1 2/5, recall@5 3/5; the curve (recall, precision): (0.2, 1), (0.4, 1), (0.4, 2/3),
// (0.4, 1/2); average precision 0.2 + 0.2; recall at 100 % precision 0.4. At two frames the
// last is right: (0.6, 3/4) adds 0.2 * 3/4. A query without a true place is not counted.
TEST(PlaceRecognitionMetricsTest, KnownAnswersByHand) {
  const std::vector<QueryAnswer> answers = {Answer(10, 10, 0.9),       Answer(20, 21, 0.8),
                                            Answer(30, 50, 0.5, {31}), Answer(40, 42, 0.3),
                                            Answer(50, -1, 0.0),       Answer(-1, 7, 5.0)};
  const PlaceRecognitionMetrics m = MetricsOf(answers, 1);
  EXPECT_EQ(m.queries, 5u);
  EXPECT_EQ(m.declined, 1u);
  EXPECT_DOUBLE_EQ(m.recall_at_1, 2.0 / 5);  // 42 is two frames from 40: wrong at tolerance 1
  EXPECT_DOUBLE_EQ(m.recall_at_5, 3.0 / 5);
  ASSERT_EQ(m.curve.size(), 4u);
  EXPECT_DOUBLE_EQ(m.curve[2].precision, 2.0 / 3);
  EXPECT_DOUBLE_EQ(m.pr_auc, 0.2 + 0.2);
  EXPECT_DOUBLE_EQ(m.recall_at_100_precision, 0.4);
  const PlaceRecognitionMetrics wide = MetricsOf(answers, 2);
  EXPECT_DOUBLE_EQ(wide.recall_at_1, 3.0 / 5);
  EXPECT_DOUBLE_EQ(wide.pr_auc, 0.2 + 0.2 + 0.2 * 3 / 4);
}

// Tied confidences are accepted together: two right and one wrong at one threshold give one
// point of precision 2/3, and recall at 100 % precision stays 0.
TEST(PlaceRecognitionMetricsTest, TiesAreOneThreshold) {
  const PlaceRecognitionMetrics m =
      MetricsOf({Answer(1, 1, 0.5), Answer(2, 9, 0.5), Answer(3, 3, 0.5)}, 0);
  ASSERT_EQ(m.curve.size(), 1u);
  EXPECT_DOUBLE_EQ(m.curve[0].precision, 2.0 / 3);
  EXPECT_DOUBLE_EQ(m.recall_at_100_precision, 0.0);
}

TEST(PairQueriesTest, ByNameThenByPositionElseAnError) {
  EXPECT_EQ(PairQueriesWithReferences({"a.png", "b.png", "c.png"}, {"c.png", "a.png"}, "").value(),
            (std::vector<int>{2, 0}));
  EXPECT_EQ(PairQueriesWithReferences({"a.png", "b.png"}, {"x.png", "y.png"}, "").value(),
            (std::vector<int>{0, 1}));
  const auto e = PairQueriesWithReferences({"a.png", "b.png"}, {"x.png"}, "");
  ASSERT_FALSE(e.ok());
  EXPECT_NE(e.status().message().find("--ground-truth"), std::string::npos);
}

}  // namespace
}  // namespace ratslam
