#include "apps/progress.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

namespace ratslam::apps {
namespace {

class FakeClock : public Clock {
 public:
  double Seconds() const override { return now; }
  double now = 100.0;
};

// What the printer wrote to a temporary file.
std::string Contents(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string s;
  for (int c; (c = std::fgetc(f)) != EOF;) s.push_back(static_cast<char>(c));
  return s;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(ProgressPrinterTest, DurationsReadNaturally) {
  EXPECT_EQ(ProgressPrinter::Duration(0.4), "0 s");
  EXPECT_EQ(ProgressPrinter::Duration(42), "42 s");
  EXPECT_EQ(ProgressPrinter::Duration(185), "3m05s");
  EXPECT_EQ(ProgressPrinter::Duration(3720), "1h02m");
}

TEST(ProgressPrinterTest, PlainLinesAtStartAndEveryTenthWithRateAndEta) {
  std::FILE* f = std::tmpfile();
  FakeClock clock;
  ProgressPrinter p(f, false, /*terminal=*/0, &clock);
  for (uint64_t done = 59; done <= 1000; done += 1) {
    clock.now = 100.0 + (done - 59) * 0.01;  // 100 per second
    p.Update({"replay", done, 1000, -1.0});
  }
  p.Finish();
  const std::vector<std::string> lines = Lines(Contents(f));
  ASSERT_EQ(lines.size(), 11u) << Contents(f);  // the start (5.9 %), then 10 % ... 100 %
  EXPECT_EQ(lines[0], "replay:   5.9% 59/1000, 0 s elapsed");  // the real share, not "0 %"
  // At 50 %: 441 done in 4.41 s since the start: 100/s, 500 left: ETA 5 s.
  EXPECT_EQ(lines[5], "replay:  50.0% 500/1000, 4 s elapsed, 100/s, ETA 5 s");
  EXPECT_EQ(lines[10], "replay: 100.0% 1000/1000, 9 s elapsed, 100/s");
  std::fclose(f);
}

TEST(ProgressPrinterTest, PhasesRestartTheClockAndDetailsPrintWithoutRestarting) {
  std::FILE* f = std::tmpfile();
  FakeClock clock;
  ProgressPrinter p(f, false, 0, &clock);
  p.Update({"visual words of map", 1, 10});
  clock.now += 50;
  p.Update({"queries", 1, 4});  // a new phase: its own elapsed time
  clock.now += 1;
  p.Update({"queries", 1, 4});  // nothing new: no line
  p.Update({"sweep, 0 failed", 0, 8});
  clock.now += 2;
  p.Update({"sweep, 1 failed", 0, 8});  // a detail changed: a line, same phase
  const std::vector<std::string> lines = Lines(Contents(f));
  ASSERT_EQ(lines.size(), 4u) << Contents(f);
  EXPECT_EQ(lines[0], "visual words of map:  10.0% 1/10, 0 s elapsed");
  EXPECT_EQ(lines[1], "queries:  25.0% 1/4, 0 s elapsed");
  EXPECT_EQ(lines[2], "sweep:   0.0% 0/8, 0 s elapsed, 0 failed");
  EXPECT_EQ(lines[3], "sweep:   0.0% 0/8, 2 s elapsed, 1 failed");
  std::fclose(f);
}

TEST(ProgressPrinterTest, ATerminalLineIsRedrawnAndEndedOnce) {
  std::FILE* f = std::tmpfile();
  FakeClock clock;
  ProgressPrinter p(f, false, /*terminal=*/1, &clock);
  for (uint64_t done = 1; done <= 5; ++done) {
    p.Update({"replay", done, 5, 1.5 * done});
    clock.now += 0.2;
  }
  p.Finish();
  const std::string text = Contents(f);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\r'), 5);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1);
  EXPECT_NE(text.find("data time 7.5 s"), std::string::npos) << text;
  std::fclose(f);
}

// A fast phase (640 queries in 0.14 s was seen) is not redrawn per step: at most ten times a
// second, and at its end.
TEST(ProgressPrinterTest, ATerminalLineIsRedrawnAtMostTenTimesASecond) {
  std::FILE* f = std::tmpfile();
  FakeClock clock;
  ProgressPrinter p(f, false, /*terminal=*/1, &clock);
  for (uint64_t done = 1; done <= 1000; ++done) {
    p.Update({"queries", done, 1000});
    clock.now += 0.001;  // one second in all
  }
  p.Finish();
  const std::string text = Contents(f);
  const auto draws = std::count(text.begin(), text.end(), '\r');
  EXPECT_GE(draws, 10);
  EXPECT_LE(draws, 12);  // every 0.1 s, plus the first and the last
  EXPECT_NE(text.find("1000/1000"), std::string::npos);
  std::fclose(f);
}

TEST(ProgressPrinterTest, QuietPrintsNothingAndAnInterruptedPhaseSaysWhereItStopped) {
  std::FILE* f = std::tmpfile();
  ProgressPrinter quiet(f, true, 0);
  quiet.Update({"replay", 1, 2});
  quiet.Finish();
  EXPECT_EQ(Contents(f), "");
  FakeClock clock;
  ProgressPrinter p(f, false, 0, &clock);
  p.Update({"replay", 1, 100});
  p.Update({"replay", 5, 100});
  p.Finish();
  const std::vector<std::string> lines = Lines(Contents(f));
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_NE(lines[1].find("5/100"), std::string::npos);
  std::fclose(f);
}

}  // namespace
}  // namespace ratslam::apps
