#include "ratslam/experience_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <numbers>

#include "common/circular.h"
#include "common/geometry.h"

namespace ratslam {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(ExperienceMapOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(ExperienceMapOptions().IsValid(&error)) << error;
}

TEST(ExperienceMapTest, LinksCarryOdometryInTheSourceFrame) {
  ExperienceMap map({});
  map.CreateExperience(0, {}, 0.0);
  map.Integrate(0.0, kPi / 2);  // turn left on the spot
  map.Integrate(2.0, 0.0);      // then 2 m forward: 2 m to the left of experience 0
  map.CreateExperience(1, {}, 1.0);
  ASSERT_EQ(map.num_links(), 1u);
  const Link& l = map.links()[0];
  EXPECT_NEAR(l.distance_m, 2.0, 1e-12);
  EXPECT_NEAR(l.heading_rad, kPi / 2, 1e-12);
  EXPECT_NEAR(l.facing_rad, kPi / 2, 1e-12);
  EXPECT_NEAR(l.duration_s, 1.0, 1e-12);
  EXPECT_NEAR(map.experience(1).x_m, 0.0, 1e-12);
  EXPECT_NEAR(map.experience(1).y_m, 2.0, 1e-12);
}

// OpenRatSLAM's exp_initial_em_deg: the start faces the initial heading, so 2 m of travel before
// the first experience puts it 2 m along that heading, and the rest of the map turns with it.
TEST(ExperienceMapTest, InitialHeadingRotatesTheWholeMapAndNothingElse) {
  auto drive = [](double initial) {
    ExperienceMapOptions o;
    o.initial_heading_rad = initial;
    ExperienceMap map(o);
    map.Integrate(2.0, 0.0);
    map.CreateExperience(0, {}, 0.0);
    map.Integrate(0.0, kPi / 2);
    map.Integrate(3.0, 0.0);
    map.CreateExperience(1, {}, 1.0);
    return map;
  };
  const ExperienceMap east = drive(0.0), north = drive(kPi / 2);
  EXPECT_NEAR(north.experience(0).x_m, 0.0, 1e-12);
  EXPECT_NEAR(north.experience(0).y_m, 2.0, 1e-12);
  EXPECT_NEAR(north.experience(0).theta_rad, kPi / 2, 1e-12);
  EXPECT_NEAR(north.experience(1).x_m, -3.0, 1e-12);  // a left turn from north faces west
  EXPECT_NEAR(north.experience(1).y_m, 2.0, 1e-12);
  for (uint32_t i = 0; i < 2; ++i) {  // each position is the unrotated one turned by 90 degrees
    EXPECT_NEAR(north.experience(i).x_m, -east.experience(i).y_m, 1e-12);
    EXPECT_NEAR(north.experience(i).y_m, east.experience(i).x_m, 1e-12);
  }
  const Link& a = east.links()[0];
  const Link& b = north.links()[0];  // links are relative: unchanged
  EXPECT_NEAR(a.distance_m, b.distance_m, 1e-12);
  EXPECT_NEAR(a.heading_rad, b.heading_rad, 1e-12);
  EXPECT_NEAR(a.facing_rad, b.facing_rad, 1e-12);
}

// Drives a square of side 10 m with a heading bias, then closes the loop back to experience 0.
ExperienceMap DriveBiasedSquare(const ExperienceMapOptions& options) {
  ExperienceMap map(options);
  map.CreateExperience(0, {}, 0.0);
  uint32_t template_id = 1;
  for (int side = 0; side < 4; ++side) {
    for (int step = 0; step < 10; ++step) {
      map.Integrate(1.0, 0.01);  // biased: 0.01 rad per metre of spurious turn
      if (side == 3 && step == 9) break;
      map.CreateExperience(template_id++, {}, 0.0);
    }
    map.Integrate(0.0, kPi / 2);
  }
  return map;
}

double LoopError(const ExperienceMap& map) {
  // Distance between the last experience and where the closing link says experience 0 is.
  const Experience& last = map.experiences().back();
  const Experience& first = map.experience(0);
  return std::hypot(last.x_m + std::cos(last.theta_rad) * 1.0 - first.x_m,
                    last.y_m + std::sin(last.theta_rad) * 1.0 - first.y_m);
}

TEST(ExperienceMapTest, RelaxationReducesLoopClosureError) {
  ExperienceMap map = DriveBiasedSquare({});
  const double before = LoopError(map);
  ASSERT_GT(before, 1.0);
  ASSERT_TRUE(map.LinkTo(0, 40.0).ok());
  // After the closing link the true geometry is a square: the last experience is at (0, -1)...
  for (int i = 0; i < 50; ++i) map.Relax();
  const double after = LoopError(map);
  EXPECT_LT(after, 0.25 * before) << "before " << before << " after " << after;
  EXPECT_EQ(map.links().back().loop_closure, true);
}

TEST(ExperienceMapTest, AConstraintClosesTheLoopLikeALinkAndKeepsTheCurrentExperience) {
  ExperienceMap map = DriveBiasedSquare({});
  const double before = LoopError(map);
  const uint32_t last = static_cast<uint32_t>(map.num_experiences() - 1);
  // Experience 0 seen from the last one: 1 m ahead, facing a quarter turn left (the square).
  StatusOr<bool> added = map.AddConstraint(last, 0, {1.0, 0.0, kPi / 2}, 40.0);
  ASSERT_TRUE(added.ok());
  EXPECT_TRUE(added.value());
  EXPECT_EQ(map.current(), last);
  EXPECT_TRUE(map.links().back().wifi_sequence);
  EXPECT_TRUE(map.links().back().loop_closure);
  EXPECT_NEAR(map.links().back().distance_m, 1.0, 1e-12);
  EXPECT_NEAR(map.links().back().facing_rad, kPi / 2, 1e-12);
  for (int i = 0; i < 50; ++i) map.Relax();
  EXPECT_LT(LoopError(map), 0.25 * before);
  // The same pair again, an experience with itself, unknown ids, NaN: nothing added.
  EXPECT_FALSE(map.AddConstraint(0, last, {1.0, 0.0, 0.0}, 41.0).value());
  EXPECT_FALSE(map.AddConstraint(3, 3, {1.0, 0.0, 0.0}, 41.0).value());
  EXPECT_FALSE(map.AddConstraint(0, 999, {1.0, 0.0, 0.0}, 41.0).ok());
  EXPECT_FALSE(map.AddConstraint(0, 5, {NAN, 0.0, 0.0}, 41.0).ok());
  EXPECT_EQ(map.links().size(), 40u);  // 39 odometry links and the constraint
}

// The square's 40 experiences are a chain of 39 one-metre links: 0 and 39 are joined by 39 m of
// links, and a sequence-closure constraint between them does not count.
TEST(ExperienceMapTest, JoinedWithinFollowsLinksOtherThanSequenceClosures) {
  ExperienceMap map = DriveBiasedSquare({});
  ASSERT_EQ(map.num_experiences(), 40u);
  EXPECT_TRUE(map.JoinedWithin(0, 39, 39.5));
  EXPECT_FALSE(map.JoinedWithin(0, 39, 38.5));
  EXPECT_TRUE(map.JoinedWithin(39, 0, 39.5));  // either way
  EXPECT_TRUE(map.JoinedWithin(5, 8, 3.5));
  EXPECT_FALSE(map.JoinedWithin(5, 8, 2.5));
  EXPECT_TRUE(map.JoinedWithin(7, 7, 0.1));
  EXPECT_FALSE(map.JoinedWithin(0, 999, 1e9));
  ASSERT_TRUE(map.AddConstraint(39, 0, {1.0, 0.0, kPi / 2}, 40.0).value());
  EXPECT_FALSE(map.JoinedWithin(0, 39, 5.0));
}

TEST(ExperienceMapCompassTest, AConstraintTakesTheCompassFacing) {
  ExperienceMap map({});
  map.CreateExperience(0, {}, 0.0, 0.3);
  map.Integrate(5.0, 0.0);
  map.CreateExperience(1, {}, 1.0);
  map.Integrate(5.0, 0.0);
  map.CreateExperience(2, {}, 2.0, 2.0);
  map.Integrate(5.0, 0.0);
  map.CreateExperience(3, {}, 3.0);  // no compass here
  ASSERT_TRUE(map.AddConstraint(0, 2, {10.0, 0.0, 3.0}, 4.0).value());
  EXPECT_NEAR(map.links().back().facing_rad, 1.7, 1e-12);  // 2.0 - 0.3, not the 3.0 measured
  ASSERT_TRUE(map.AddConstraint(0, 3, {15.0, 0.0, 0.25}, 4.0).value());
  EXPECT_NEAR(map.links().back().facing_rad, 0.25, 1e-12);
}

TEST(ExperienceMapTest, AnchoredFirstExperienceDoesNotMove) {
  ExperienceMapOptions options;
  options.anchor_first_experience = true;
  ExperienceMap map = DriveBiasedSquare(options);
  ASSERT_TRUE(map.LinkTo(0, 40.0).ok());
  for (int i = 0; i < 20; ++i) map.Relax();
  EXPECT_EQ(map.experience(0).x_m, 0.0);
  EXPECT_EQ(map.experience(0).y_m, 0.0);
  EXPECT_EQ(map.experience(0).theta_rad, 0.0);
}

TEST(ExperienceMapTest, LinkToExistingLinkedExperienceAddsNoDuplicate) {
  ExperienceMap map({});
  map.CreateExperience(0, {}, 0.0);
  map.Integrate(1.0, 0.0);
  map.CreateExperience(1, {}, 1.0);
  auto added = map.LinkTo(0, 2.0);
  ASSERT_TRUE(added.ok());
  EXPECT_FALSE(added.value());
  EXPECT_EQ(map.num_links(), 1u);
  EXPECT_EQ(map.current(), 0u);
  EXPECT_FALSE(map.LinkTo(7, 3.0).ok());
}

TEST(ExperienceMapTest, ShortestPathUsesLoopClosureShortcut) {
  ExperienceMap map = DriveBiasedSquare({});
  ASSERT_TRUE(map.LinkTo(0, 40.0).ok());
  const uint32_t last = static_cast<uint32_t>(map.num_experiences() - 1);
  const std::vector<uint32_t> path = map.ShortestPath(last, 0);
  ASSERT_EQ(path.size(), 2u);  // straight over the closing link, not around the square
  EXPECT_EQ(path.front(), last);
  EXPECT_EQ(path.back(), 0u);
  const std::vector<uint32_t> long_way = map.ShortestPath(0, 20);
  ASSERT_EQ(long_way.size(), 21u);
  EXPECT_TRUE(map.ShortestPath(0, 999).empty());
}

}  // namespace
}  // namespace ratslam

namespace ratslam {
namespace {

// Driving out along x, turning round, and coming back past the start: with a compass, the return
// link to the first experience has the facing the compass says (pi) whatever the odometry says,
// and dead reckoning continues facing the way the robot really faces.
TEST(ExperienceMapCompassTest, RevisitInOppositeDirectionUsesCompassFacing) {
  ExperienceMap map({});
  map.CreateExperience(0, {}, 0.0, 0.0);
  map.Integrate(5.0, 0.0);
  map.CreateExperience(1, {}, 1.0, 0.0);
  map.Integrate(5.0, 0.0);
  map.CreateExperience(2, {}, 2.0, 0.0);
  map.Integrate(0.0, 3.0);  // odometry says 3.0 rad; the compass says pi
  map.Integrate(10.0, 0.0);
  auto added = map.LinkTo(0, 3.0, M_PI);
  ASSERT_TRUE(added.ok());
  ASSERT_TRUE(added.value());
  const Link& closing = map.links().back();
  EXPECT_TRUE(closing.loop_closure);
  EXPECT_NEAR(std::abs(closing.facing_rad), 0.0, 1e-12);  // both experiences faced 0
  // Now at experience 0 facing pi: one more metre of travel goes to -x.
  map.Integrate(1.0, 0.0);
  double x, y, theta;
  map.CurrentPose(&x, &y, &theta);
  EXPECT_NEAR(x, -1.0, 1e-9);
  EXPECT_NEAR(std::abs(theta), M_PI, 1e-9);
}

TEST(ExperienceMapCompassTest, NewLinksTakeCompassFacing) {
  ExperienceMap map({});
  map.CreateExperience(0, {}, 0.0, 0.5);
  map.Integrate(1.0, 0.9);  // odometric turn 0.9 rad; compass says 0.3 rad
  map.CreateExperience(1, {}, 1.0, 0.8);
  EXPECT_NEAR(map.links().back().facing_rad, 0.3, 1e-12);
}

}  // namespace
}  // namespace ratslam

namespace ratslam {
namespace {

// The full scheme as first written (std::cos/sin per link, fmod-based WrapAngle): the full scheme
// must stay equal to it bit for bit.
void ReferenceFullRelax(std::vector<Experience>& ex, const std::vector<Link>& links, int sweeps,
                        double c) {
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    for (const Link& l : links) {
      Experience& a = ex[l.from];
      Experience& b = ex[l.to];
      const double px = a.x_m + l.distance_m * std::cos(a.theta_rad + l.heading_rad);
      const double py = a.y_m + l.distance_m * std::sin(a.theta_rad + l.heading_rad);
      const double ex_m = b.x_m - px, ey_m = b.y_m - py;
      const double et = WrapAngle(b.theta_rad - (a.theta_rad + l.facing_rad));
      a.x_m += ex_m * c;
      a.y_m += ey_m * c;
      a.theta_rad = WrapAngle(a.theta_rad + et * c);
      b.x_m -= ex_m * c;
      b.y_m -= ey_m * c;
      b.theta_rad = WrapAngle(b.theta_rad - et * c);
    }
  }
}

ExperienceMapOptions Scheme(RelaxationScheme scheme) {
  ExperienceMapOptions o;
  o.relaxation_scheme = scheme;
  return o;
}

// A long route: a chain with a spurious turn, closing back onto experience `i - 60` every 40.
ExperienceMap DriveLongRoute(const ExperienceMapOptions& options, int n) {
  ExperienceMap map(options);
  for (int i = 0; i < n; ++i) {
    map.Integrate(1.0, 0.11);
    map.CreateExperience(i, {}, i);
    map.Relax();
    if (i >= 60 && i % 40 == 0) {
      EXPECT_TRUE(map.LinkTo(static_cast<uint32_t>(i - 60), i).ok());
      map.Relax();
    }
  }
  return map;
}

// Laps of a 20 m x 10 m rectangle with places every metre, odometry 3 % long with 0.02 rad of
// spurious turn per metre: the first lap creates an experience per place, later laps link to
// them, relaxing after every action. Returns the map error against the true places (RMSE after
// rigid alignment) and counts link updates.
double LapsMapError(const ExperienceMapOptions& options, int laps, uint64_t* link_updates) {
  ExperienceMap map(options);
  std::vector<Point2> truth;
  for (int s = 0; s < 60; ++s) {
    if (s < 20)
      truth.push_back({double(s), 0.0});
    else if (s < 30)
      truth.push_back({20.0, double(s - 20)});
    else if (s < 50)
      truth.push_back({double(50 - s), 10.0});
    else
      truth.push_back({0.0, double(60 - s)});
  }
  for (int lap = 0; lap < laps; ++lap) {
    for (int s = 0; s < 60; ++s) {
      if (lap == 0) {
        map.CreateExperience(s, {}, s);
      } else {
        EXPECT_TRUE(map.LinkTo(s, 60.0 * lap + s).ok());
      }
      map.Relax();
      const bool corner = s == 19 || s == 29 || s == 49 || s == 59;
      map.Integrate(1.03, 0.02 + (corner ? kPi / 2 : 0.0));
    }
  }
  std::vector<Point2> estimate;
  for (const Experience& e : map.experiences()) estimate.push_back({e.x_m, e.y_m});
  *link_updates = map.relaxation_link_updates();
  return AlignRigid2D(estimate, truth)->rmse_m;
}
double LapsMapError(RelaxationScheme scheme, int laps, uint64_t* link_updates) {
  return LapsMapError(Scheme(scheme), laps, link_updates);
}

TEST(RelaxationSchemeTest, IncrementalIsAsAccurateAsFullForAFractionOfTheWork) {
  uint64_t full_updates = 0, incremental_updates = 0, none = 0;
  const double dead_reckoning = LapsMapError(RelaxationScheme::kFull, 1, &none);
  const double full = LapsMapError(RelaxationScheme::kFull, 6, &full_updates);
  const double incremental = LapsMapError(RelaxationScheme::kIncremental, 6, &incremental_updates);
  // Relaxation pays: the laps' links take most of the drift out (checked for both schemes).
  EXPECT_LT(full, 0.5 * dead_reckoning) << full << " vs " << dead_reckoning;
  EXPECT_LE(incremental, 1.02 * full + 1e-3) << incremental << " vs " << full;
  EXPECT_LT(incremental_updates * 5, full_updates) << incremental_updates << " vs " << full_updates;
}

// A region cap smaller than the loop still takes most of the drift out, and bounds every
// action's cost by the passes over the cap plus the links the action added.
TEST(RelaxationSchemeTest, CappedRegionBoundsEachActionAndStillCorrects) {
  uint64_t none = 0, uncapped_updates = 0, capped_updates = 0;
  const double dead_reckoning = LapsMapError(RelaxationScheme::kFull, 1, &none);
  ExperienceMapOptions uncapped = Scheme(RelaxationScheme::kIncremental);
  uncapped.relaxation_max_region_links = 0;
  ExperienceMapOptions capped = uncapped;
  capped.relaxation_max_region_links = 40;  // a lap is 60 links
  const double free_error = LapsMapError(uncapped, 6, &uncapped_updates);
  const double capped_error = LapsMapError(capped, 6, &capped_updates);
  EXPECT_LT(capped_error, 0.5 * dead_reckoning) << capped_error << " vs " << dead_reckoning;
  // Not free: the window leaves part of each lap's correction undone.
  EXPECT_GT(capped_error, free_error);
  std::cout << "laps map error: dead reckoning " << dead_reckoning << " m, uncapped " << free_error
            << " m (" << uncapped_updates << " link updates), capped at 40 links " << capped_error
            << " m (" << capped_updates << ")\n";

  ExperienceMap map(capped);
  uint64_t worst = 0;
  for (int i = 0; i < 1200; ++i) {
    map.Integrate(1.0, 0.11);
    map.CreateExperience(i, {}, i);
    uint64_t before = map.relaxation_link_updates();
    if (i >= 60 && i % 40 == 0) {
      ASSERT_TRUE(map.LinkTo(static_cast<uint32_t>(i - 60), i).ok());
    }
    map.Relax();
    worst = std::max(worst, map.relaxation_link_updates() - before);
    ASSERT_LE(map.state().relaxation_pending_links.size(), 40u);
  }
  EXPECT_GT(map.relaxation_capped_passes(), 0u);
  // Ten passes over at most the cap plus the action's two new links.
  EXPECT_LE(worst, 10u * (40u + 2u));
  EXPECT_GT(worst, 10u * 20u);  // the cap, not a settled map, is what bounds it
}

TEST(RelaxationSchemeTest, NoCapNeededNoCapUsed) {
  // Below the cap, the cap changes nothing: the default map equals an uncapped one exactly.
  ExperienceMapOptions uncapped = Scheme(RelaxationScheme::kIncremental);
  uncapped.relaxation_max_region_links = 0;
  ExperienceMap a = DriveLongRoute(Scheme(RelaxationScheme::kIncremental), 400);
  ExperienceMap b = DriveLongRoute(uncapped, 400);
  EXPECT_EQ(a.relaxation_capped_passes(), 0u);
  ASSERT_EQ(a.num_experiences(), b.num_experiences());
  for (size_t i = 0; i < a.num_experiences(); ++i) {
    ASSERT_EQ(a.experience(i).x_m, b.experience(i).x_m) << i;
    ASSERT_EQ(a.experience(i).theta_rad, b.experience(i).theta_rad) << i;
  }
}

TEST(RelaxationSchemeTest, FullSchemeEqualsTheOriginalBitForBit) {
  ExperienceMap map = DriveBiasedSquare(Scheme(RelaxationScheme::kFull));
  ASSERT_TRUE(map.LinkTo(0, 40.0).ok());
  std::vector<Experience> reference = map.experiences();
  for (int i = 0; i < 7; ++i) {
    map.Relax();
    ReferenceFullRelax(reference, map.links(), 10, 0.5);
  }
  for (size_t i = 0; i < reference.size(); ++i) {
    ASSERT_EQ(map.experience(i).x_m, reference[i].x_m) << i;
    ASSERT_EQ(map.experience(i).y_m, reference[i].y_m) << i;
    ASSERT_EQ(map.experience(i).theta_rad, reference[i].theta_rad) << i;
  }
}

TEST(RelaxationSchemeTest, IncrementalSettlesAndThenDoesNothing) {
  ExperienceMap map = DriveLongRoute(Scheme(RelaxationScheme::kIncremental), 400);
  for (int i = 0; i < 2000 && !map.state().relaxation_pending_links.empty(); ++i) map.Relax();
  EXPECT_TRUE(map.state().relaxation_pending_links.empty());
  const std::vector<Experience> settled = map.experiences();
  const uint64_t before = map.relaxation_link_updates();
  map.Relax();
  EXPECT_EQ(map.relaxation_link_updates(), before);
  EXPECT_EQ(map.experience(123).x_m, settled[123].x_m);
}

TEST(RelaxationSchemeTest, ExtendingAConvergedMapCostsOneLinkUpdate) {
  ExperienceMap map = DriveLongRoute(Scheme(RelaxationScheme::kIncremental), 200);
  for (int i = 0; i < 2000 && !map.state().relaxation_pending_links.empty(); ++i) map.Relax();
  ASSERT_TRUE(map.state().relaxation_pending_links.empty());
  const uint64_t before = map.relaxation_link_updates();
  map.Relax();  // nothing changed
  EXPECT_EQ(map.relaxation_link_updates(), before);
  for (int i = 0; i < 50; ++i) {
    map.Integrate(1.0, 0.11);
    map.CreateExperience(1000 + i, {}, 1000.0 + i);
    map.Relax();
  }
  EXPECT_EQ(map.relaxation_link_updates(), before + 50);
}

TEST(RelaxationSchemeTest, ResumedStateRelaxesAsTheUninterruptedMap) {
  const ExperienceMapOptions options = Scheme(RelaxationScheme::kIncremental);
  ExperienceMap whole = DriveBiasedSquare(options);
  ASSERT_TRUE(whole.LinkTo(0, 40.0).ok());
  whole.Relax();  // leaves work pending: ten passes do not settle a 40-link loop
  ASSERT_FALSE(whole.state().relaxation_pending_links.empty());
  ExperienceMap resumed(options);
  ASSERT_TRUE(resumed.SetState(whole.state()).ok());
  for (int i = 0; i < 5; ++i) {
    whole.Relax();
    resumed.Relax();
  }
  for (size_t i = 0; i < whole.num_experiences(); ++i) {
    ASSERT_EQ(whole.experience(i).x_m, resumed.experience(i).x_m) << i;
    ASSERT_EQ(whole.experience(i).theta_rad, resumed.experience(i).theta_rad) << i;
  }
  EXPECT_EQ(whole.state().relaxation_pending_links, resumed.state().relaxation_pending_links);
}

TEST(RelaxationSchemeTest, SetStateRefusesInconsistentRelaxationWork) {
  ExperienceMap map = DriveBiasedSquare(Scheme(RelaxationScheme::kIncremental));
  const ExperienceMap::State good = map.state();
  auto refused = [&](auto&& edit) {
    ExperienceMap::State s = good;
    edit(s);
    ExperienceMap target({});
    return !target.SetState(s).ok();
  };
  EXPECT_TRUE(refused([](auto& s) { s.relaxation_pending_links = {3, 2}; }));
  EXPECT_TRUE(refused([](auto& s) { s.relaxation_pending_links = {1, 1}; }));
  EXPECT_TRUE(refused([](auto& s) { s.relaxation_pending_links = {uint32_t(s.links.size())}; }));
  ExperienceMap target({});
  EXPECT_TRUE(target.SetState(good).ok());
}

TEST(RelaxationSchemeTest, SchemeNamesRoundTrip) {
  for (RelaxationScheme s :
       {RelaxationScheme::kFull, RelaxationScheme::kIncremental, RelaxationScheme::kLeastSquares}) {
    EXPECT_EQ(RelaxationSchemeFromString(ToString(s)).value(), s);
  }
  EXPECT_FALSE(RelaxationSchemeFromString("fast").ok());
}

// The weighted squared residual of a map's links (the least-squares objective), evaluated by the
// optimiser with no iteration.
double GraphCost(const ExperienceMap& map) {
  std::vector<Experience> copy = map.experiences();
  return OptimisePoseGraph(&copy, map.links(), map.options().Noise(), 0)->initial_cost;
}

// Least squares works only at loop closures (no link updates; one optimisation per closure), and
// its map minimises the objective: its cost is below what ten full relaxation passes per action
// leave on the same route.
TEST(RelaxationSchemeTest, LeastSquaresOptimisesAtClosuresOnly) {
  ExperienceMap full = DriveLongRoute(Scheme(RelaxationScheme::kFull), 400);
  ExperienceMap ls = DriveLongRoute(Scheme(RelaxationScheme::kLeastSquares), 400);
  EXPECT_EQ(ls.relaxation_link_updates(), 0u);
  EXPECT_EQ(ls.least_squares_runs(), 8u);  // the closures at 80, 120, ..., 360
  EXPECT_EQ(ls.least_squares_failures(), 0u);
  EXPECT_TRUE(ls.state().relaxation_pending_links.empty());
  EXPECT_LT(GraphCost(ls), GraphCost(full)) << GraphCost(ls) << " vs " << GraphCost(full);
}

TEST(RelaxationSchemeTest, LeastSquaresIsAsAccurateAsFull) {
  uint64_t updates = 0;
  const double dead_reckoning = LapsMapError(RelaxationScheme::kFull, 1, &updates);
  const double full = LapsMapError(RelaxationScheme::kFull, 6, &updates);
  const double ls = LapsMapError(RelaxationScheme::kLeastSquares, 6, &updates);
  EXPECT_EQ(updates, 0u);
  EXPECT_LT(ls, 0.5 * dead_reckoning) << ls << " vs " << dead_reckoning;
  EXPECT_LE(ls, 1.02 * full + 1e-3) << ls << " vs " << full;
  std::printf("laps map error: dead reckoning %.4f m, full %.4f m, least squares %.4f m\n",
              dead_reckoning, full, ls);
}

}  // namespace
}  // namespace ratslam
