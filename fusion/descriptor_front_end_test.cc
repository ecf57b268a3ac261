// The descriptor front end (front_end.h, kDescriptors) and its table, on hand-made descriptors
// whose cosine similarities are known.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "fusion/front_end.h"

namespace ratslam::fusion {
namespace {

// Images at times 0, 1, 2, ... with the given descriptors.
struct Fixture {
  dataset::Dataset dataset;
  dataset::DescriptorMatrix matrix;
};
Fixture Make(const std::vector<std::vector<float>>& rows) {
  Fixture f;
  f.dataset.name = "hand";
  f.matrix.rows = rows.size();
  f.matrix.cols = rows.front().size();
  for (size_t i = 0; i < rows.size(); ++i) {
    ImageRow image;
    image.time_s = static_cast<double>(i);
    image.file = std::to_string(i) + ".png";
    f.dataset.images.push_back(image);
    f.matrix.values.insert(f.matrix.values.end(), rows[i].begin(), rows[i].end());
  }
  return f;
}

std::unique_ptr<FrontEnd> FrontEndFor(const Fixture& f, const DescriptorOptions& options) {
  auto table = DescriptorTable::Make(f.matrix, f.dataset, "hand.npy");
  EXPECT_TRUE(table.ok()) << table.status().message();
  FrontEndSettings settings;
  settings.front_end.kind = FrontEndKind::kDescriptors;
  settings.descriptors = options;
  FrontEndResources resources;
  resources.descriptors = *table;
  return CreateFrontEnd(settings, resources);
}

FrameDecision Frame(FrontEnd& front_end, double time_s) {
  auto d = front_end.OnImage(time_s, GrayImage());
  EXPECT_TRUE(d.ok()) << d.status().message();
  return d.value().value();
}

// cos(a, b) = 0.8 between (1, 0, 0) and (0.8, 0.6, 0); scaling never matters.
TEST(DescriptorFrontEndTest, MatchesByCosineSimilarityAgainstTheThreshold) {
  const Fixture f = Make({{1, 0, 0}, {0, 0, 5}, {0.8f, 0.6f, 0}, {40, 0, 0}, {0, 0.1f, 2}});
  DescriptorOptions options;
  options.min_similarity = 0.85;
  options.recency_s = 0.0;
  auto front_end = FrontEndFor(f, options);
  EXPECT_TRUE(front_end->WantsImages());
  EXPECT_FALSE(front_end->NeedsPixels());
  EXPECT_TRUE(Frame(*front_end, 0).view.is_new);
  EXPECT_TRUE(Frame(*front_end, 1).view.is_new);
  const FrameDecision below = Frame(*front_end, 2);  // 0.8 < 0.85: a new place
  EXPECT_TRUE(below.view.is_new);
  EXPECT_EQ(below.view.template_id, 2u);
  const FrameDecision same = Frame(*front_end, 3);  // 40 * (1, 0, 0): cosine 1 with template 0
  EXPECT_FALSE(same.view.is_new);
  EXPECT_EQ(same.view.template_id, 0u);
  EXPECT_TRUE(same.view.allow_injection);
  EXPECT_EQ(same.source, DecisionSource::kCamera);
  const FrameDecision near = Frame(*front_end, 4);  // cosine 0.9988 with template 1
  EXPECT_EQ(near.view.template_id, 1u);
  EXPECT_EQ(front_end->size(), 3u);
}

TEST(DescriptorFrontEndTest, RecentMatchesAreReusedWithoutInjection) {
  const Fixture f = Make({{1, 0}, {1, 0.01f}, {0, 1}, {1, 0}});
  DescriptorOptions options;
  options.min_similarity = 0.9;
  options.recency_s = 2.5;
  auto front_end = FrontEndFor(f, options);
  Frame(*front_end, 0);
  const FrameDecision recent = Frame(*front_end, 1);  // 1 s after template 0
  EXPECT_FALSE(recent.view.is_new);
  EXPECT_EQ(recent.view.template_id, 0u);
  EXPECT_FALSE(recent.view.allow_injection);
  EXPECT_TRUE(recent.recent);
  Frame(*front_end, 2);
  const FrameDecision old = Frame(*front_end, 3);  // 3 s after: old enough
  EXPECT_EQ(old.view.template_id, 0u);
  EXPECT_TRUE(old.view.allow_injection);
  EXPECT_FALSE(old.recent);
}

// A saved map's templates were made on another clock: after SettleForLocalisation a match to
// one of them injects, however recent its time stamp looks; templates made later keep the rule.
TEST(DescriptorFrontEndTest, TemplatesOfASavedMapAreNeverRecent) {
  const Fixture f = Make({{1, 0}, {1, 0}, {0, 1}, {0, 1}});
  DescriptorOptions options;
  options.recency_s = 100.0;
  auto front_end = FrontEndFor(f, options);
  Frame(*front_end, 0);
  EXPECT_TRUE(Frame(*front_end, 1).recent);
  front_end->SettleForLocalisation();
  const FrameDecision mapped = Frame(*front_end, 1);
  EXPECT_FALSE(mapped.recent);
  EXPECT_TRUE(mapped.view.allow_injection);
  EXPECT_TRUE(Frame(*front_end, 2).view.is_new);
  EXPECT_TRUE(Frame(*front_end, 3).recent);
}

TEST(DescriptorFrontEndTest, StateRoundTripsAndRejectsWhatItDidNotWrite) {
  const Fixture f = Make({{1, 2, 3}, {3, 2, 1}, {1, 2, 3.1f}});
  DescriptorOptions options;
  options.recency_s = 0.0;
  auto a = FrontEndFor(f, options);
  Frame(*a, 0);
  Frame(*a, 1);
  auto b = FrontEndFor(f, options);
  ASSERT_TRUE(b->DecodeState(a->EncodeState()).ok());
  EXPECT_EQ(b->size(), 2u);
  EXPECT_EQ(Frame(*a, 2).view.template_id, Frame(*b, 2).view.template_id);
  EXPECT_EQ(a->EncodeState(), b->EncodeState());

  std::string truncated = a->EncodeState();
  truncated.pop_back();
  EXPECT_FALSE(b->DecodeState(truncated).ok());
  // A template scaled away from unit length (the first float of the first row doubled).
  std::string scaled = a->EncodeState();
  float v = 0;
  const size_t first_value = 8 + 8;  // dimensions, then the vector's length
  std::memcpy(&v, scaled.data() + first_value, 4);
  v *= 2;
  std::memcpy(scaled.data() + first_value, &v, 4);
  const Status s = b->DecodeState(scaled);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("not a unit vector"), std::string::npos) << s.message();
  // A map made with other descriptors (two dimensions) does not fit three-dimensional ones.
  const Fixture other = Make({{1, 0}});
  auto c = FrontEndFor(other, options);
  Frame(*c, 0);
  const Status wrong = b->DecodeState(c->EncodeState());
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.message().find("2 dimensions, this data set's 3"), std::string::npos)
      << wrong.message();
}

TEST(DescriptorFrontEndTest, TableRefusesMismatchedCountsZeroRowsAndUnknownTimes) {
  Fixture f = Make({{1, 0}, {0, 1}});
  f.matrix.rows = 1;
  f.matrix.values.resize(2);
  auto count = DescriptorTable::Make(f.matrix, f.dataset, "d.npy");
  ASSERT_FALSE(count.ok());
  EXPECT_NE(count.status().message().find("1 descriptors, but data set 'hand' has 2 camera images"),
            std::string::npos)
      << count.status().message();
  const Fixture zero = Make({{1, 0}, {0, 0}});
  auto zeros = DescriptorTable::Make(zero.matrix, zero.dataset, "d.npy");
  ASSERT_FALSE(zeros.ok());
  EXPECT_NE(zeros.status().message().find("descriptor 1 (image at 1 s) has no length"),
            std::string::npos)
      << zeros.status().message();
  // Two images at one time need one descriptor.
  Fixture twins = Make({{1, 0}, {0, 1}});
  twins.dataset.images[1].time_s = 0.0;
  EXPECT_FALSE(DescriptorTable::Make(twins.matrix, twins.dataset, "d.npy").ok());
  twins.matrix.values = {1, 0, 2, 0};
  auto same = DescriptorTable::Make(twins.matrix, twins.dataset, "d.npy");
  ASSERT_TRUE(same.ok());
  EXPECT_EQ((*same)->size(), 1u);

  auto front_end = FrontEndFor(Make({{1, 0}}), DescriptorOptions());
  auto unknown = front_end->OnImage(0.5, GrayImage());
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("no descriptor for the image at 0.5 s"),
            std::string::npos);
}

TEST(DescriptorFrontEndTest, OptionsAreValidatedAndKindsParse) {
  DescriptorOptions options;
  std::string error;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.min_similarity = 1.5;
  EXPECT_FALSE(options.IsValid(&error));
  options.min_similarity = 0.5;
  options.file.clear();
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_EQ(FrontEndKindFromString("descriptors").value(), FrontEndKind::kDescriptors);
  EXPECT_EQ(FrontEndKindFromString("custom").value(), FrontEndKind::kCustom);
  FrontEndSettings settings;
  settings.front_end.kind = FrontEndKind::kCustom;
  EXPECT_THROW(CreateFrontEnd(settings), std::invalid_argument);
}

// Without a file the front end takes descriptors fed one by one (a live source, Python) and
// decides exactly as from a file; images then say where their descriptors should come from.
TEST(DescriptorFrontEndTest, FedDescriptorsDecideAsTheFileDoes) {
  const std::vector<std::vector<float>> rows = {{1, 2, 3}, {3, 2, 1},    {1.1f, 2, 3},
                                                {0, 0, 1}, {3, 2.2f, 1}, {-1, 0, 0}};
  DescriptorOptions options;
  options.recency_s = 1.5;
  auto from_file = FrontEndFor(Make(rows), options);
  FrontEndSettings settings;
  settings.front_end.kind = FrontEndKind::kDescriptors;
  settings.descriptors = options;
  auto fed = CreateFrontEnd(settings);
  const Status no_file = fed->OnImage(0, GrayImage()).status();
  EXPECT_NE(no_file.message().find("no descriptor file"), std::string::npos) << no_file.message();
  for (size_t i = 0; i < rows.size(); ++i) {
    const FrameDecision a = Frame(*from_file, static_cast<double>(i));
    auto b = fed->OnDescriptor(static_cast<double>(i), rows[i]);
    ASSERT_TRUE(b.ok()) << b.status().message();
    EXPECT_EQ(a.view.template_id, b.value()->view.template_id) << i;
    EXPECT_EQ(a.view.is_new, b.value()->view.is_new) << i;
    EXPECT_EQ(a.recent, b.value()->recent) << i;
  }
  EXPECT_EQ(fed->EncodeState(), from_file->EncodeState());
  EXPECT_FALSE(fed->OnDescriptor(9, {1, 2}).ok());  // another dimension
  EXPECT_FALSE(fed->OnDescriptor(9, {0, 0, 0}).ok());
  EXPECT_FALSE(fed->OnDescriptor(9, {1, NAN, 0}).ok());
  // A map saved from a file-fed run continues in a fed one (which adopts its dimension).
  auto continued = CreateFrontEnd(settings);
  ASSERT_TRUE(continued->DecodeState(from_file->EncodeState()).ok());
  EXPECT_FALSE(continued->OnDescriptor(10, {1, 0}).ok());
  EXPECT_EQ(continued->OnDescriptor(10, {1, 2, 3}).value()->view.template_id, 0u);
  // Other front ends take no descriptors.
  FrontEndSettings classic;
  EXPECT_FALSE(CreateFrontEnd(classic)->OnDescriptor(0, {1}).ok());
}

}  // namespace
}  // namespace ratslam::fusion
