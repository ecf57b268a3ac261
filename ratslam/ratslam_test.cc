#include "ratslam/ratslam.h"

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

namespace ratslam {
namespace {

TEST(RatslamOptionsTest, DefaultsAreValid) {
  std::string error;
  EXPECT_TRUE(RatslamOptions().IsValid(&error)) << error;
}

TEST(RatslamOptionsTest, ErrorNamesSectionAndField) {
  RatslamOptions options;
  options.action.match_distance_cells = -1;
  std::string error;
  ASSERT_FALSE(options.IsValid(&error));
  EXPECT_EQ(error.rfind("action.match_distance_cells", 0), 0u) << error;
}

TEST(RatslamTest, NewViewsCreateExperiencesAndLinks) {
  Ratslam slam({});
  for (uint32_t i = 0; i < 5; ++i) {
    ASSERT_TRUE(slam.OnView({i * 1.0, i, true, 0.0}).ok());
    auto action = slam.OnOdometry({i * 1.0, 1.0, 0.0});
    ASSERT_TRUE(action.ok());
    EXPECT_EQ(action.value(), ActionKind::kCreatedExperience);
  }
  EXPECT_EQ(slam.experience_map().num_experiences(), 5u);
  EXPECT_EQ(slam.experience_map().num_links(), 4u);
  EXPECT_EQ(slam.counters().loop_closures, 0u);
}

TEST(RatslamTest, RejectsOdometryThatIsNotFinite) {
  Ratslam slam({});
  EXPECT_FALSE(slam.OnOdometry({0.0, std::numeric_limits<double>::quiet_NaN(), 0.0}).ok());
}

RatslamOptions LineOptions() {
  RatslamOptions options;
  options.local_view.skip_recent_templates = 5;
  return options;
}

// A line of 30 new places 1 m apart, one per second from *t.
void MapLine(Ratslam* slam, double* t) {
  for (uint32_t i = 0; i < 30; ++i, *t += 1.0) {
    ASSERT_TRUE(slam->OnView({*t, i, true, 0.0}).ok());
    ASSERT_TRUE(slam->OnOdometry({*t, 1.0, 0.0}).ok());
  }
}

TEST(RatslamTest, RevisitedPlaceClosesTheLoop) {
  // Out and back along a line of 30 places 1 m apart, then the same places again in order.
  Ratslam slam(LineOptions());
  double t = 0.0;
  MapLine(&slam, &t);
  // Drive home with a drifting odometry (teleport back to the start: heading unchanged), then
  // see the first places again; the injections pull the packet back and links close the loop.
  for (int lap = 0; lap < 3; ++lap) {
    for (uint32_t i = 0; i < 30; ++i, t += 1.0) {
      ASSERT_TRUE(slam.OnView({t, i, false, 0.0}).ok());
      ASSERT_TRUE(slam.OnOdometry({t, 1.0, 0.0}).ok());
    }
  }
  EXPECT_GT(slam.counters().loop_closures, 0u);
  EXPECT_GT(slam.counters().injections, 0u);
}

// A frozen map (localisation only): places seen again move the current experience to theirs and
// dead reckoning restarts there; nothing joins the map; a view the map does not hold injects
// nothing and is counted.
TEST(RatslamTest, FrozenMapRecognisesPlacesAndNeverGrows) {
  Ratslam slam(LineOptions());
  double t = 0.0;
  MapLine(&slam, &t);
  const size_t experiences = slam.experience_map().num_experiences();
  const size_t links = slam.experience_map().num_links();
  slam.FreezeMap(t);
  EXPECT_TRUE(slam.frozen());
  EXPECT_FALSE(slam.experience_map().current().has_value());  // lost until a place is seen
  ASSERT_TRUE(slam.OnView({t, 30, true, 0.0}).ok());          // a place the map does not know
  auto action = slam.OnOdometry({t, 1.0, 0.0});
  ASSERT_TRUE(action.ok());
  EXPECT_EQ(action.value(), ActionKind::kNone);
  EXPECT_EQ(slam.counters().injections, 0u);
  EXPECT_EQ(slam.localisation_counters().unmapped_views, 1u);
  EXPECT_FALSE(slam.current_template().has_value());
  t += 1.0;
  for (int lap = 0; lap < 3; ++lap) {
    for (uint32_t i = 0; i < 30; ++i, t += 1.0) {
      ASSERT_TRUE(slam.OnView({t, i, false, 0.0}).ok());
      action = slam.OnOdometry({t, 1.0, 0.0});
      ASSERT_TRUE(action.ok());
      EXPECT_NE(action.value(), ActionKind::kCreatedExperience);
      EXPECT_NE(action.value(), ActionKind::kLinkedExisting);
    }
  }
  EXPECT_EQ(slam.experience_map().num_experiences(), experiences);
  EXPECT_EQ(slam.experience_map().num_links(), links);
  EXPECT_GT(slam.localisation_counters().recognitions, 10u);
  EXPECT_GT(slam.counters().injections, 0u);
  // At the end of the line, where place 29 was stored (after its odometry step, as then).
  ASSERT_TRUE(slam.experience_map().current().has_value());
  EXPECT_EQ(slam.experience_map().experience(*slam.experience_map().current()).template_id, 29u);
  EXPECT_NEAR(slam.experience_map().offset().forward_m, 0.0, 1e-9);
}

// Relocalisation on a frozen map: a lost robot that views place 17 of the line is at place 17's
// experience at once (no injections needed), with its pose cells there; it stays there while
// dead reckoning is within the lost distance, and is relocalised again once it is beyond. Without
// a lost distance the same view leaves it lost (the injections have not moved the packet yet).
TEST(RatslamTest, LostRobotIsRelocalisedByAViewOfTheMap) {
  Ratslam slam(LineOptions());
  double t = 0.0;
  MapLine(&slam, &t);
  Ratslam plain = slam;
  slam.FreezeMap(t, 5.0);
  plain.FreezeMap(t);
  const auto experience_of = [](const Ratslam& r, uint32_t place) {
    for (uint32_t id : r.local_view().at(place).experience_ids) return id;
    return UINT32_MAX;
  };
  const uint32_t e17 = experience_of(slam, 17);
  ASSERT_NE(e17, UINT32_MAX);
  EXPECT_TRUE(slam.Lost(5.0));
  ASSERT_TRUE(slam.OnView({t, 17, false, 0.0}).ok());
  ASSERT_TRUE(plain.OnView({t, 17, false, 0.0}).ok());
  ASSERT_TRUE(slam.experience_map().current().has_value());
  EXPECT_EQ(*slam.experience_map().current(), e17);
  EXPECT_FALSE(slam.Lost(5.0));
  EXPECT_EQ(slam.localisation_counters().relocalisations, 1u);
  EXPECT_EQ(slam.localisation_counters().recognitions, 1u);
  EXPECT_EQ(slam.counters().injections, 0u);
  const PoseCellPosition cells = slam.pose_cells().BestPosition();
  const PoseCellPosition stored = slam.experience_map().experience(e17).pose_cells;
  EXPECT_LT(PoseCellDistance(cells, stored, LineOptions().pose_cells.dim_xy_cells,
                             LineOptions().pose_cells.dim_theta_cells),
            0.5);
  EXPECT_FALSE(plain.experience_map().current().has_value());
  EXPECT_TRUE(plain.Lost(5.0));
  // Three metres on, seeing place 17 again: not lost, so no relocalisation.
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(slam.OnOdometry({t += 1.0, 1.0, 0.0}).ok());
  ASSERT_TRUE(slam.OnView({t, 17, false, 0.0}).ok());
  EXPECT_EQ(slam.localisation_counters().relocalisations, 1u);
  // Three more (six from place 17): lost; a view of place 5 puts it there.
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(slam.OnOdometry({t += 1.0, 1.0, 0.0}).ok());
  EXPECT_TRUE(slam.Lost(5.0));
  // This time the compass says the robot faces a quarter turn from when place 5 was stored:
  // the packet faces that way too, as an injection would.
  ASSERT_TRUE(slam.OnView({t, 5, false, std::numbers::pi / 2}).ok());
  EXPECT_EQ(slam.localisation_counters().relocalisations, 2u);
  EXPECT_EQ(*slam.experience_map().current(), experience_of(slam, 5));
  const int theta_cells = LineOptions().pose_cells.dim_theta_cells;
  const PoseCellPosition turned =
      slam.experience_map().experience(experience_of(slam, 5)).pose_cells;
  EXPECT_NEAR(PoseCellDistance(slam.pose_cells().BestPosition(),
                               {turned.x, turned.y, turned.theta + theta_cells / 4.0},
                               LineOptions().pose_cells.dim_xy_cells, theta_cells),
              0.0, 0.5);
  // A view of a place the map does not hold never relocalises.
  for (int k = 0; k < 6; ++k) ASSERT_TRUE(slam.OnOdometry({t += 1.0, 1.0, 0.0}).ok());
  ASSERT_TRUE(slam.OnView({t, 30, true, 0.0}).ok());
  EXPECT_EQ(slam.localisation_counters().relocalisations, 2u);
  EXPECT_TRUE(slam.Lost(5.0));
}

TEST(RatslamTest, StateRoundTripContinuesIdentically) {
  Ratslam a({});
  for (uint32_t i = 0; i < 20; ++i) {
    ASSERT_TRUE(a.OnView({i * 1.0, i % 12, i < 12, 0.0}).ok());
    ASSERT_TRUE(a.OnOdometry({i * 1.0, 0.8, 0.1}).ok());
  }
  Ratslam b({});
  ASSERT_TRUE(b.SetState(a.GetState()).ok());
  for (uint32_t i = 20; i < 40; ++i) {
    for (Ratslam* s : {&a, &b}) {
      ASSERT_TRUE(s->OnView({i * 1.0, i % 12, false, 0.0}).ok());
      ASSERT_TRUE(s->OnOdometry({i * 1.0, 0.8, 0.1}).ok());
    }
  }
  ASSERT_EQ(a.experience_map().num_experiences(), b.experience_map().num_experiences());
  for (size_t i = 0; i < a.experience_map().num_experiences(); ++i) {
    EXPECT_EQ(a.experience_map().experience(i).x_m, b.experience_map().experience(i).x_m);
  }
}

TEST(RatslamTest, FailedSetStateChangesNothing) {
  Ratslam a({});
  for (uint32_t i = 0; i < 5; ++i) {
    ASSERT_TRUE(a.OnView({i * 1.0, i, true, 0.0}).ok());
    ASSERT_TRUE(a.OnOdometry({i * 1.0, 1.0, 0.0}).ok());
  }
  Ratslam::State bad = a.GetState();
  bad.experience_map.links.push_back(
      {99, 0, 1234, 1.0, 0.0, 0.0, 1.0, false});  // no such experience
  Ratslam b({});
  const auto before = b.pose_cells().BestPosition();
  EXPECT_FALSE(b.SetState(bad).ok());
  EXPECT_EQ(b.local_view().size(), 0u);  // the valid parts were not applied either
  EXPECT_EQ(b.experience_map().num_experiences(), 0u);
  EXPECT_EQ(b.pose_cells().BestPosition().x, before.x);
}

// Two experiences of one template lie within match distance of the pose and the nearer one is
// not current: refuse_ambiguous_links makes no link (and counts it); the default links.
TEST(RatslamTest, RefuseAmbiguousLinksDecidesBetweenTwoCandidates) {
  for (bool refuse : {false, true}) {
    RatslamOptions options;
    options.action.refuse_ambiguous_links = refuse;
    Ratslam slam(options);
    ASSERT_TRUE(slam.OnView({0.0, 0, true, 0.0}).ok());
    ASSERT_TRUE(slam.OnOdometry({0.0, 0.0, 0.0}).ok());  // experience 0 at x = 0
    ASSERT_TRUE(slam.OnOdometry({1.0, 2.5, 0.0}).ok());  // 2.5 cells on: experience 1
    ASSERT_EQ(slam.experience_map().num_experiences(), 2u);
    ASSERT_EQ(*slam.experience_map().current(), 1u);
    // Back 1.6 cells: 0.9 from experience 0, 1.6 from experience 1; both within 2.
    StatusOr<ActionKind> action = slam.OnOdometry({2.0, -1.6, 0.0});
    ASSERT_TRUE(action.ok());
    if (refuse) {
      EXPECT_EQ(action.value(), ActionKind::kRefusedAmbiguous);
      EXPECT_EQ(slam.counters().refused_ambiguous, 1u);
      EXPECT_EQ(slam.experience_map().num_links(), 1u);
      EXPECT_EQ(*slam.experience_map().current(), 1u);
    } else {
      // Experiences 0 and 1 are joined already (1 was made from 0): no new link, but the map
      // moves to experience 0.
      EXPECT_EQ(action.value(), ActionKind::kLinkedExisting);
      EXPECT_EQ(slam.experience_map().num_links(), 1u);
      EXPECT_EQ(*slam.experience_map().current(), 0u);
    }
  }
}

// A place seen again facing the other way: with match_heading the pose-cell theta differs by
// half the ring, so a new experience is made; without it the old one is re-used (a loop closure).
TEST(RatslamTest, MatchHeadingFalseReusesAPlaceSeenTheOtherWay) {
  for (bool match_heading : {true, false}) {
    RatslamOptions options;
    options.action.match_heading = match_heading;
    Ratslam slam(options);
    ASSERT_TRUE(slam.OnView({0.0, 0, true, 0.0}).ok());
    ASSERT_TRUE(slam.OnOdometry({0.0, 0.0, 0.0}).ok());  // experience 0, facing +x
    ASSERT_TRUE(slam.OnView({1.0, 1, true, 0.0}).ok());
    ASSERT_TRUE(slam.OnOdometry({1.0, 3.0, 0.0}).ok());               // experience 1, 3 cells on
    ASSERT_TRUE(slam.OnOdometry({2.0, 0.0, std::numbers::pi}).ok());  // turn round
    ASSERT_TRUE(slam.OnOdometry({3.0, 3.0, 0.0}).ok());               // walk back
    const size_t before = slam.experience_map().num_experiences();
    ASSERT_TRUE(slam.OnView({4.0, 0, false, 0.0}).ok());  // template 0 again, facing -x
    StatusOr<ActionKind> action = slam.OnOdometry({4.0, 0.0, 0.0});
    ASSERT_TRUE(action.ok());
    if (match_heading) {
      EXPECT_EQ(action.value(), ActionKind::kCreatedExperience);
      EXPECT_EQ(slam.experience_map().num_experiences(), before + 1);
    } else {
      EXPECT_EQ(action.value(), ActionKind::kLinkedExisting);
      EXPECT_EQ(*slam.experience_map().current(), 0u);
      EXPECT_EQ(slam.counters().loop_closures, 1u);
    }
  }
}

// A restored state is untrusted input: every corruption below once loaded and crashed (or
// poisoned) the next step. Each must be refused with a message, and the spine left unchanged.
TEST(RatslamTest, SetStateRefusesDanglingIdsAndNonFiniteValues) {
  Ratslam a({});
  for (uint32_t i = 0; i < 30; ++i) {
    ASSERT_TRUE(a.OnView({i * 1.0, i % 10, i < 10, 0.0}).ok());
    ASSERT_TRUE(a.OnOdometry({i * 1.0, 0.8, 0.3}).ok());
  }
  const Ratslam::State good = a.GetState();
  ASSERT_GE(good.experience_map.experiences.size(), 3u);
  ASSERT_GE(good.experience_map.links.size(), 2u);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<std::pair<const char*, std::function<void(Ratslam::State&)>>> corruptions = {
      {"template -> missing experience",  // the ASan SEGV at ratslam.cc:77
       [](auto& s) { s.local_view.templates[0].experience_ids.push_back(4000); }},
      {"template -> another template's experience",
       [](auto& s) {
         const uint32_t owner = s.experience_map.experiences[0].template_id;
         s.local_view.templates[owner == 0 ? 1 : 0].experience_ids.push_back(0);
       }},
      {"experience -> missing link",
       [](auto& s) { s.experience_map.experiences[0].link_ids = {77}; }},
      {"experience -> link that does not join it",
       [](auto& s) {
         auto& e = s.experience_map.experiences;
         const auto& l = s.experience_map.links;
         for (uint32_t k = 0; k < l.size(); ++k) {
           if (l[k].from != e.back().id && l[k].to != e.back().id) {
             e.back().link_ids.push_back(k);
             return;
           }
         }
       }},
      {"experience x NaN", [nan](auto& s) { s.experience_map.experiences[1].x_m = nan; }},
      {"experience y huge", [](auto& s) { s.experience_map.experiences[1].y_m = 1e300; }},
      {"link distance infinite",
       [](auto& s) {
         s.experience_map.links[0].distance_m = std::numeric_limits<double>::infinity();
       }},
      {"offset NaN", [nan](auto& s) { s.experience_map.offset.left_m = nan; }},
      {"pose-cell residual NaN", [nan](auto& s) { s.pose_cells.residual_x_cells[3] = nan; }},
      {"pose-cell residual beyond a cell",
       [](auto& s) { s.pose_cells.residual_theta_cells = 7.0; }},
      {"template off the grid", [](auto& s) { s.local_view.templates[2].pose_cells.x = -1e9; }},
      {"template theta NaN", [nan](auto& s) { s.local_view.templates[2].pose_cells.theta = nan; }},
      {"experience off the grid",
       [](auto& s) { s.experience_map.experiences[0].pose_cells.y = 1e6; }},
      {"template decay NaN", [nan](auto& s) { s.local_view.templates[1].decay = nan; }},
      {"template matched in the future",
       [](auto& s) { s.local_view.templates[1].decay_frame = s.local_view.frame + 5; }},
      {"compass NaN", [nan](auto& s) { s.compass_heading_rad = nan; }},
      {"current template missing", [](auto& s) { s.current_template = 500; }},
  };
  for (const auto& [name, corrupt] : corruptions) {
    Ratslam::State bad = good;
    corrupt(bad);
    Ratslam b({});
    const Status status = b.SetState(bad);
    EXPECT_FALSE(status.ok()) << name;
    EXPECT_FALSE(status.message().empty()) << name;
    EXPECT_EQ(b.local_view().size(), 0u) << name;
  }
  // The untouched state still restores and runs on.
  Ratslam b({});
  ASSERT_TRUE(b.SetState(good).ok());
  for (uint32_t i = 30; i < 60; ++i) {
    ASSERT_TRUE(b.OnView({i * 1.0, i % 10, false, 0.0}).ok());
    ASSERT_TRUE(b.OnOdometry({i * 1.0, 0.8, 0.3}).ok());
  }
}

}  // namespace
}  // namespace ratslam
