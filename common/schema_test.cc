#include "common/schema.h"

#include <gtest/gtest.h>

#include <limits>
#include <sstream>

#include "common/toml_binder.h"

namespace ratslam::schema {
namespace {

struct Example {
  int cells = 3;
  double gain_m = 1.5;
  bool on = true;
  std::string path = "a/b.csv";
  std::vector<double> times_s = {0.0, 1.0};

  template <typename V>
  void VisitFields(V&& v) {
    v("cells", cells, "odd cell count", Unit("cells").Odd().AtLeast(1));
    v("gain_m", gain_m, "a gain", Unit("m").Above(0).Below(2));
    v("on", on, "a switch", Any());
    v("path", path, "a file", Any().RelativePath());
    v("times_s", times_s, "start times", Unit("s").NonNegative().Increasing());
  }
};

std::string ErrorOf(const Example& e) {
  std::string error;
  return CheckFields(e, &error) ? "" : error;
}

TEST(SchemaTest, DefaultsPassAndEachRuleRefusesItsBreak) {
  EXPECT_EQ(ErrorOf(Example()), "");
  Example e;
  e.cells = 4;
  EXPECT_EQ(ErrorOf(e), "cells: must be odd and at least 1");
  e = Example();
  e.cells = -1;
  EXPECT_EQ(ErrorOf(e), "cells: must be odd and at least 1");
  e = Example();
  e.gain_m = 2.0;  // the upper end is open
  EXPECT_EQ(ErrorOf(e), "gain_m: must be in (0, 2)");
  e.gain_m = 0.0;
  EXPECT_EQ(ErrorOf(e), "gain_m: must be in (0, 2)");
  e.gain_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ErrorOf(e), "gain_m: must be a finite number");
  e = Example();
  e.path = "../outside.csv";
  EXPECT_EQ(ErrorOf(e), "path: must be a relative path inside the folder");
  e.path = "/etc/passwd";
  EXPECT_EQ(ErrorOf(e), "path: must be a relative path inside the folder");
  e.path = "";
  EXPECT_EQ(ErrorOf(e), "path: must not be empty");
  e = Example();
  e.times_s = {1.0, 0.5};
  EXPECT_EQ(ErrorOf(e), "times_s: must be increasing");
  e.times_s = {-1.0};
  EXPECT_EQ(ErrorOf(e), "times_s: element 0: must be zero or more");
}

TEST(SchemaTest, UnboundedDoublesMustStillBeFinite) {
  EXPECT_EQ(Violation(std::numeric_limits<double>::infinity(), Unit("dBm")),
            "must be a finite number");
  EXPECT_EQ(Violation(-1e300, Unit("dBm")), "");
}

TEST(SchemaTest, DescribesRulesForDocumentation) {
  EXPECT_EQ(DescribeRule(Unit("m").Positive()), "(m; > 0)");
  EXPECT_EQ(DescribeRule(Unit("").Within(0, 1)), "(in [0, 1])");
  EXPECT_EQ(DescribeRule(Unit("cells").Odd().AtLeast(1)), "(cells; odd, >= 1)");
  EXPECT_EQ(DescribeRule(Any()), "");
  EXPECT_EQ(DescribeRule(Unit("s")), "(s)");
}

StatusOr<Example> Bind(const std::string& text) {
  StatusOr<toml::table> table = ParseToml(text, "x.toml");
  if (!table.ok()) return table.status();
  Example e;
  TableBinder binder(*table, "[example]", "example.", "x.toml");
  e.VisitFields(binder);
  RATSLAM_RETURN_IF_ERROR(binder.Finish());
  return e;
}

TEST(TomlBinderTest, ReadsTypesAndChecksRulesWithTheLine) {
  StatusOr<Example> e = Bind("cells = 5\ngain_m = 1\ntimes_s = [0, 2.5]\n");
  ASSERT_TRUE(e.ok()) << e.status().message();
  EXPECT_EQ(e->cells, 5);
  EXPECT_EQ(e->gain_m, 1.0);
  EXPECT_EQ(e->times_s, (std::vector<double>{0.0, 2.5}));
  EXPECT_EQ(Bind("\ncells = 6\n").status().message(),
            "x.toml:2: example.cells: must be odd and at least 1");
  EXPECT_EQ(Bind("cells = 1.5\n").status().message(),
            "x.toml:1: example.cells: expected an integer");
  EXPECT_EQ(Bind("gain_m = nan\n").status().message(),
            "x.toml:1: example.gain_m: must be a finite number");
  EXPECT_EQ(Bind("times_s = [0, \"a\"]\n").status().message(),
            "x.toml:1: example.times_s: element 1: expected a number");
  EXPECT_EQ(Bind("cells = 99999999999\n").status().message(),
            "x.toml:1: example.cells: integer out of range");
  EXPECT_EQ(Bind("on = true\ncels = 3\n").status().message(),
            "x.toml:2: unknown key 'cels' in [example] (did you mean 'cells'?)");
}

TEST(TomlBinderTest, PrintedFieldsReadBackToTheSameValues) {
  Example original;
  original.cells = 7;
  original.gain_m = 0.1 + 0.2;  // not a short decimal: the printer must keep every bit
  original.path = "x \"quoted\"\\name";
  original.times_s = {0.0, 1e-9, 3.25};
  std::ostringstream out;
  TablePrinter printer(out, true);
  original.VisitFields(printer);
  EXPECT_NE(out.str().find("# odd cell count (cells; odd, >= 1)\ncells = 7\n"), std::string::npos);
  StatusOr<Example> back = Bind(out.str());
  ASSERT_TRUE(back.ok()) << back.status().message() << "\n" << out.str();
  EXPECT_EQ(back->cells, original.cells);
  EXPECT_EQ(back->gain_m, original.gain_m);
  EXPECT_EQ(back->path, original.path);
  EXPECT_EQ(back->times_s, original.times_s);
}

TEST(TomlBinderTest, SuggestsOnlyCloseNames) {
  EXPECT_EQ(DidYouMean("recency", {"recency_s", "recency_templates"}),
            " (did you mean 'recency_s'?)");
  EXPECT_EQ(DidYouMean("q", {"recency_s"}), "");
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
}

}  // namespace
}  // namespace ratslam::schema
