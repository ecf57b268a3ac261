#include "io/config.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "common/scratch_dir.h"
#include "tests/generated_block.h"

namespace ratslam::io {
namespace {

// One fresh folder per test process (two checkouts testing at once never collide).
const ScratchDir& TestScratch() {
  static const ScratchDir dir("ratslam_test");
  return dir;
}

std::string ErrorOf(const std::string& text) {
  StatusOr<fusion::PipelineOptions> o = ParseConfig(text, "c.toml");
  EXPECT_FALSE(o.ok());
  return o.status().message();
}

TEST(ConfigTest, DefaultsAreValidAndEmptyFileGivesDefaults) {
  std::string error;
  EXPECT_TRUE(fusion::PipelineOptions().IsValid(&error)) << error;
  StatusOr<fusion::PipelineOptions> o = ParseConfig("", "empty.toml");
  ASSERT_TRUE(o.ok());
  EXPECT_EQ(PrintConfig(o.value()), PrintConfig(fusion::PipelineOptions()));
}

TEST(ConfigTest, ReadsValuesAndAcceptsIntegersForReals) {
  StatusOr<fusion::PipelineOptions> o = ParseConfig(
      "[pose_cells]\ndim_xy_cells = 30\ncell_size_m = 2\n[camera]\npanoramic = true\n"
      "[front_end]\nkind = \"classic_camera\"\n",
      "c.toml");
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->ratslam.pose_cells.dim_xy_cells, 30);
  EXPECT_EQ(o->ratslam.pose_cells.cell_size_m, 2.0);
  EXPECT_TRUE(o->sensors.classic_camera.panoramic);
}

// A phone log given as the configuration is named as a data set, small or large (a log over the
// size limit once read "config file is larger than 1048576 bytes").
TEST(ConfigTest, ADataSetGivenAsTheConfigurationIsNamedAsOne) {
  for (const size_t lines : {size_t{3}, size_t{30000}}) {
    const std::filesystem::path log =
        TestScratch().path() / ("walk" + std::to_string(lines) + ".txt");
    {
      std::ofstream out(log);
      out << "% IPIN log\n";
      for (size_t i = 0; i < lines; ++i) out << "ACCE;" << i * 0.02 << ";1;0.1;0.2;9.8;3\n";
    }
    StatusOr<fusion::PipelineOptions> options = LoadConfigFile(log.string());
    ASSERT_FALSE(options.ok());
    EXPECT_NE(options.status().message().find(log.string() +
                                              " is a data set, not a configuration: give it as "
                                              "--data"),
              std::string::npos)
        << options.status().message();
  }
}

// Paths inside a configuration file are read relative to the file, wherever the program runs;
// absolute ones stay as they are.
TEST(ConfigTest, PathsInAConfigurationAreRelativeToItsFile) {
  const std::filesystem::path folder = TestScratch().path() / "configs_here";
  std::filesystem::create_directories(folder);
  const std::filesystem::path config = folder / "paths.toml";
  std::ofstream(config) << "[visual_model]\ntraining_images = \"../images\"\n"
                           "file = \"/abs/model.bin\"\n[video]\nodometry_log = \"odo.txt\"\n";
  StatusOr<fusion::PipelineOptions> o = LoadConfigFile(config.string());
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(
      o->sensors.fabmap.visual_model.training_images,
      (std::filesystem::absolute(TestScratch().path()) / "images").lexically_normal().string());
  EXPECT_EQ(o->sensors.fabmap.visual_model.file, "/abs/model.bin");
  EXPECT_EQ(o->video.odometry_log,
            (std::filesystem::absolute(folder) / "odo.txt").lexically_normal().string());
}

TEST(ConfigTest, UnknownKeyNamesLine) {
  EXPECT_EQ(ErrorOf("[pose_cells]\ndim_xy_cells = 30\ndim_xy_cell = 3\n"),
            "c.toml:3: unknown key 'dim_xy_cell' in [pose_cells] (did you mean 'dim_xy_cells'?)");
  // Nothing close: no suggestion.
  EXPECT_EQ(ErrorOf("[pose_cells]\nbanana = 3\n"),
            "c.toml:2: unknown key 'banana' in [pose_cells]");
}

TEST(ConfigTest, UnknownSectionNamesLine) {
  EXPECT_EQ(ErrorOf("\n[posecells]\nx = 1\n"),
            "c.toml:2: unknown section 'posecells' (did you mean 'pose_cells'?)");
  EXPECT_EQ(ErrorOf("[zebra]\nx = 1\n"), "c.toml:1: unknown section 'zebra'");
}

TEST(ConfigTest, WrongTypeNamesLineAndKey) {
  EXPECT_EQ(ErrorOf("[experience_map]\n\nrelaxation_sweeps = 2.5\n"),
            "c.toml:3: experience_map.relaxation_sweeps: expected an integer");
  EXPECT_EQ(ErrorOf("[camera]\npanoramic = 1\n"),
            "c.toml:2: camera.panoramic: expected true or false");
}

TEST(ConfigTest, OutOfRangeValueNamesLine) {
  EXPECT_EQ(ErrorOf("[pose_cells]\n\n\nexcitation_size_cells = 4\n"),
            "c.toml:4: pose_cells.excitation_size_cells: must be odd and at least 1");
}

// Every section's range errors name the line: the FABMAP sections once reported "c.toml:" with no
// line because their checks wrote "field reason" instead of "field: reason".
TEST(ConfigTest, OutOfRangeValueNamesLineInEverySection) {
  const std::pair<const char*, const char*> cases[] = {
      {"fabmap_front_end", "match_probability = 2.0"},
      {"fabmap", "max_candidates = 0"},
      {"fabmap_model", "p_new_place = 1.5"},
      {"visual_detector", "p_observed_given_exists = 0.0"},
      {"wifi_detector", "p_observed_given_exists = 1.0"},
      {"visual_words", "max_features = 0"},
      {"vocabulary", "words = 0"},
      {"visual_model", "training_image_step = 0"},
      {"wifi_words", "bins = 0"},
      {"virtual_wifi", "samples = 0"},
      {"evaluation", "map_fraction = 1.5"},
      {"camera", "match_threshold = -1.0"},
      {"local_view", "energy_limit = 0.0"},
  };
  for (const auto& [section, line] : cases) {
    const std::string error =
        ErrorOf("# a comment\n[" + std::string(section) + "]\n\n" + std::string(line) + "\n");
    const std::string key = std::string(line).substr(0, std::string(line).find(' '));
    EXPECT_EQ(error.rfind("c.toml:4: " + std::string(section) + "." + key + ": ", 0), 0u) << error;
  }
}

// A valid config must not exhaust memory: this grid once passed and needed 24 GiB.
TEST(ConfigTest, PoseCellGridSizeIsBounded) {
  const std::string error = ErrorOf("[pose_cells]\ndim_xy_cells = 32768\ndim_theta_cells = 1\n");
  EXPECT_EQ(error.rfind("c.toml:2: pose_cells.dim_xy_cells: grid", 0), 0u) << error;
  EXPECT_TRUE(ParseConfig("[pose_cells]\ndim_xy_cells = 200\ndim_theta_cells = 36\n", "c").ok());
}

TEST(ConfigTest, LocateConfigReadsItsSectionsAndRefusesOthers) {
  StatusOr<phone::LocateOptions> o = ParseLocateConfig(
      "[particle_filter]\nlikelihood = \"product\"\nparticles = 500\n[wifi_map]\n"
      "length_scale_m = 2.0\n",
      "l.toml");
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->particle_filter.likelihood, phone::ScanLikelihood::kProduct);
  EXPECT_EQ(o->particle_filter.particles, 500);
  EXPECT_EQ(o->wifi_map.length_scale_m, 2.0);
  StatusOr<phone::LocateOptions> back = ParseLocateConfig(PrintLocateConfig(*o), "p.toml");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(PrintLocateConfig(*back), PrintLocateConfig(*o));
  // A replay section, a typo and a bad enum name the file and line.
  StatusOr<phone::LocateOptions> replay = ParseLocateConfig("[camera]\nshift_px = 3\n", "l.toml");
  ASSERT_FALSE(replay.ok());
  EXPECT_NE(replay.status().message().find("unknown section 'camera'"), std::string::npos);
  StatusOr<phone::LocateOptions> typo =
      ParseLocateConfig("[particle_filter]\nparticle = 5\n", "l.toml");
  ASSERT_FALSE(typo.ok());
  EXPECT_NE(typo.status().message().find("l.toml:2"), std::string::npos) << typo.status().message();
  StatusOr<phone::LocateOptions> bad =
      ParseLocateConfig("[particle_filter]\nlikelihood = \"mean\"\n", "l.toml");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("sum, product"), std::string::npos);
}

TEST(ConfigTest, BadEnumListsValidNames) {
  const std::string error = ErrorOf("[front_end]\nkind = \"wifi\"\n");
  EXPECT_NE(error.find("c.toml:2"), std::string::npos) << error;
  EXPECT_NE(error.find("valid: classic_camera, fused"), std::string::npos) << error;
}

TEST(ConfigTest, SyntaxErrorNamesLine) {
  EXPECT_EQ(ErrorOf("[camera]\nshift_px = = 3\n").rfind("c.toml:2:", 0), 0u);
}

TEST(ConfigTest, PrintThenParseRoundTrips) {
  fusion::PipelineOptions options;
  options.ratslam.pose_cells.cell_size_m = 0.1 + 0.2;
  options.sensors.classic_camera.match_threshold = 1e-7;
  options.ratslam.action.refuse_ambiguous_links = true;
  StatusOr<fusion::PipelineOptions> back = ParseConfig(PrintConfig(options), "printed");
  ASSERT_TRUE(back.ok()) << back.status().message();
  EXPECT_EQ(back->ratslam.pose_cells.cell_size_m, 0.1 + 0.2);
  EXPECT_EQ(back->sensors.classic_camera.match_threshold, 1e-7);
  EXPECT_EQ(PrintConfig(back.value()), PrintConfig(options));
  EXPECT_EQ(ConfigFingerprint(back.value()), ConfigFingerprint(options));
  EXPECT_NE(ConfigFingerprint(fusion::PipelineOptions()), ConfigFingerprint(options));
}

TEST(ConfigTest, ImportsOpenRatslamIniAndReportsUnusedKeys) {
  const auto path = TestScratch().path() / "ratslam_import_test.ini";
  std::ofstream(path) << "[general]\ntopic_root=irat_red\n\n[ratslam]\n"
                         "vt_match_threshold=0.085\npc_dim_xy=30\npc_cell_x_size=0.015\n"
                         "exp_loops=20\nvt_active_decay = 1.5 ; comment\nvt_panoramic=1\n"
                         "template_x_size=60\n[draw]\nenable=1\n";
  StatusOr<ImportedConfig> imported = ImportOpenRatslamIni(path.string());
  ASSERT_TRUE(imported.ok()) << imported.status().message();
  const fusion::PipelineOptions& o = imported->options;
  EXPECT_EQ(o.sensors.classic_camera.match_threshold, 0.085);
  EXPECT_EQ(o.ratslam.pose_cells.dim_xy_cells, 30);
  EXPECT_EQ(o.ratslam.pose_cells.cell_size_m, 0.015);
  EXPECT_EQ(o.ratslam.experience_map.relaxation_sweeps, 20);
  EXPECT_EQ(o.ratslam.local_view.decay_floor, 1.5);
  EXPECT_TRUE(o.sensors.classic_camera.panoramic);
  ASSERT_EQ(imported->notes.size(), 2u);
  EXPECT_NE(imported->notes[0].find(":2: [general] topic_root"), std::string::npos);
  EXPECT_NE(imported->notes[0].find("(-> [bag] image_topic = \"/irat_red/camera/image\", "
                                    "odometry_topic = \"/irat_red/odom\")"),
            std::string::npos)
      << imported->notes[0];
  EXPECT_EQ(o.bag.image_topic, "/irat_red/camera/image");
  // With OpenRatSLAM's visual odometry node configured, odometry is not read from the bag.
  std::ofstream(path) << "[general]\ntopic_root=/newcollege/\n[visual_odometry]\n"
                         "vtrans_image_x_min=195\n[ratslam]\ntemplate_x_size=60\n";
  StatusOr<ImportedConfig> vo = ImportOpenRatslamIni(path.string());
  ASSERT_TRUE(vo.ok()) << vo.status().message();
  EXPECT_EQ(vo->options.bag.image_topic, "/newcollege/camera/image");
  EXPECT_EQ(vo->options.bag.odometry_topic, "");
  std::ofstream(path) << "[general]\ntopic_root=my robot\n[ratslam]\ntemplate_x_size=60\n";
  StatusOr<ImportedConfig> spaced = ImportOpenRatslamIni(path.string());
  ASSERT_FALSE(spaced.ok());
  EXPECT_NE(spaced.status().message().find(":2: [general] topic_root = my robot"),
            std::string::npos)
      << spaced.status().message();
  // Misspelt keys are errors with the key meant (their value was once lost without a word); keys
  // of OpenRatSLAM's viewer and keys near none stay notes.
  std::ofstream(path) << "[ratslam]\nvt_match_treshold=0.085\n";
  StatusOr<ImportedConfig> typo = ImportOpenRatslamIni(path.string());
  ASSERT_FALSE(typo.ok());
  EXPECT_NE(
      typo.status().message().find(":2: [ratslam] unknown key 'vt_match_treshold' (did you mean "
                                   "'vt_match_threshold'?)"),
      std::string::npos)
      << typo.status().message();
  std::ofstream(path) << "[ratslam]\nvt_restore=0.04\n";
  StatusOr<ImportedConfig> short_name = ImportOpenRatslamIni(path.string());
  ASSERT_FALSE(short_name.ok());
  EXPECT_NE(short_name.status().message().find("(did you mean 'pc_vt_restore'?)"),
            std::string::npos)
      << short_name.status().message();
  std::ofstream(path) << "[ratslam]\ntemplate_x_size=60\n[draw]\nexp_map_size=500\n"
                         "posecells_size=250\n[other]\nfoo_bar_baz=1\n";
  StatusOr<ImportedConfig> viewer = ImportOpenRatslamIni(path.string());
  ASSERT_TRUE(viewer.ok()) << viewer.status().message();
  EXPECT_EQ(viewer->notes.size(), 3u);
  std::ofstream(path) << "[ratslam]\npc_dim_xy=thirty\n";
  StatusOr<ImportedConfig> bad = ImportOpenRatslamIni(path.string());
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find(":2: pc_dim_xy: not a number"), std::string::npos);
  std::filesystem::remove(path);
}

// OpenRatSLAM's three shipped configurations, rebuilt from the values the facts file lists for
// them (../shared/reference/openratslam-facts.md, "Values set by the shipped configs"; keys not
// listed there are left out, as the files leave them out): every key they leave out takes
// OpenRatSLAM's default, checked by hand against the facts file's key table.
TEST(ConfigTest, ShippedOpenRatslamConfigsImportWithOpenRatslamsDefaults) {
  const auto dir = TestScratch().path();
  struct Shipped {
    const char* name;
    const char* ratslam;  // the [ratslam] section
  };
  const Shipped shipped[] = {
      {"stlucia",
       "image_crop_x_min=40\nimage_crop_x_max=600\nimage_crop_y_min=150\nimage_crop_y_max=300\n"
       "template_x_size=60\ntemplate_y_size=10\nvt_match_threshold=0.085\nvt_shift_match=5\n"
       "vt_step_match=1\nvt_panoramic=0\nvt_normalisation=0.4\nvt_patch_normalise=0\n"
       "pc_vt_restore=0.04\npc_dim_xy=30\npc_cell_x_size=2\npc_vt_inject_energy=0.15\n"
       "vt_active_decay=1.0\nexp_delta_pc_threshold=1.0\nexp_loops=20\n"},
      {"irataus",
       "image_crop_y_min=0\nimage_crop_y_max=150\ntemplate_x_size=60\ntemplate_y_size=20\n"
       "vt_match_threshold=0.03\nvt_shift_match=4\nvt_step_match=1\nvt_panoramic=0\n"
       "vt_normalisation=0\nvt_patch_normalise=0\npc_dim_xy=11\npc_cell_x_size=0.015\n"
       "pc_vt_inject_energy=0.1\nvt_active_decay=1.0\nexp_delta_pc_threshold=2\n"
       "exp_loops=20\nexp_initial_em_deg=140\n"},
      {"newcollege",
       "template_x_size=60\ntemplate_y_size=10\nvt_match_threshold=0.054\nvt_panoramic=1\n"
       "vt_normalisation=0\nvt_patch_normalise=2\npc_dim_xy=30\npc_cell_x_size=1.0\n"
       "pc_vt_inject_energy=0.2\nvt_active_decay=1.0\nexp_delta_pc_threshold=2.0\n"
       "exp_loops=100\n"},
  };
  std::map<std::string, fusion::PipelineOptions> got;
  for (const Shipped& c : shipped) {
    const auto path = dir / (std::string("config_") + c.name + ".txt");
    std::ofstream(path) << "[general]\ntopic_root=" << c.name << "\n[ratslam]\n"
                        << c.ratslam << "[draw]\nenable=1\n";
    StatusOr<ImportedConfig> imported = ImportOpenRatslamIni(path.string());
    ASSERT_TRUE(imported.ok()) << c.name << ": " << imported.status().message();
    // Reloads: the converted file parses back to the same options.
    StatusOr<fusion::PipelineOptions> back = ParseConfig(PrintConfig(imported->options), c.name);
    ASSERT_TRUE(back.ok()) << back.status().message();
    EXPECT_EQ(PrintConfig(*back), PrintConfig(imported->options));
    got[c.name] = imported->options;
  }
  const fusion::PipelineOptions& nc = got["newcollege"];
  EXPECT_EQ(nc.sensors.classic_camera.shift_step_px, 5);  // left out: 12 rotations, 30 deg apart
  EXPECT_EQ(nc.sensors.classic_camera.shift_px, 25);
  EXPECT_EQ(nc.ratslam.local_view.decay_restore_per_frame, 0.05);
  EXPECT_EQ(nc.sensors.classic_camera.crop_left_px, 0);
  EXPECT_EQ(nc.sensors.classic_camera.crop_right_px, -1);  // the image width
  EXPECT_EQ(nc.sensors.classic_camera.patch_normalisation_radius_px, 2);
  EXPECT_TRUE(nc.sensors.classic_camera.panoramic);
  for (const auto& [name, o] : got) {
    SCOPED_TRACE(name);
    EXPECT_EQ(o.ratslam.pose_cells.dim_theta_cells, 36);
    EXPECT_EQ(o.ratslam.pose_cells.excitation_size_cells, 7);
    EXPECT_EQ(o.ratslam.pose_cells.inhibition_size_cells, 5);
    EXPECT_EQ(o.ratslam.pose_cells.excitation_variance_cells2, 1.0);  // sigma 1
    EXPECT_EQ(o.ratslam.pose_cells.inhibition_variance_cells2, 4.0);  // sigma 2
    EXPECT_EQ(o.ratslam.pose_cells.global_inhibition, 0.00002);
    EXPECT_EQ(o.ratslam.experience_map.relaxation_correction, 0.5);
    EXPECT_EQ(o.ratslam.experience_map.relaxation_scheme, RelaxationScheme::kFull);
  }
  const fusion::PipelineOptions& sl = got["stlucia"];
  EXPECT_EQ(sl.sensors.classic_camera.shift_px, 5);
  EXPECT_EQ(sl.sensors.classic_camera.shift_step_px, 1);
  EXPECT_EQ(sl.sensors.classic_camera.crop_left_px, 40);
  EXPECT_EQ(sl.sensors.classic_camera.crop_bottom_px, 300);
  EXPECT_EQ(sl.sensors.classic_camera.global_normalisation_mean, 0.4);
  EXPECT_EQ(sl.ratslam.local_view.decay_restore_per_frame, 0.04);
  EXPECT_EQ(sl.ratslam.pose_cells.cell_size_m, 2.0);
  EXPECT_EQ(sl.ratslam.action.match_distance_cells, 1.0);
  EXPECT_EQ(sl.ratslam.experience_map.relaxation_sweeps, 20);
  const fusion::PipelineOptions& ir = got["irataus"];
  EXPECT_EQ(ir.sensors.classic_camera.template_height_px, 20);
  EXPECT_EQ(ir.sensors.classic_camera.shift_px, 4);
  EXPECT_EQ(ir.ratslam.local_view.injection_gain, 0.1);
  EXPECT_EQ(ir.ratslam.pose_cells.dim_xy_cells, 11);
  // exp_initial_em_deg: 140 in the iRat file, OpenRatSLAM's default 90 in the others.
  EXPECT_DOUBLE_EQ(ir.ratslam.experience_map.initial_heading_rad, 140 * M_PI / 180);
  EXPECT_DOUBLE_EQ(sl.ratslam.experience_map.initial_heading_rad, M_PI / 2);
  EXPECT_DOUBLE_EQ(nc.ratslam.experience_map.initial_heading_rad, M_PI / 2);
  EXPECT_EQ(nc.bag.image_topic, "/newcollege/camera/image");
  EXPECT_EQ(nc.bag.odometry_topic, "/newcollege/odom");
  for (const auto& [name, o] : got) EXPECT_FALSE(o.visual_odometry.enabled) << name;
  // St Lucia's [visual_odometry] section (facts file, "Values set by the shipped configs") turns
  // on OpenRatSLAM's visual odometry with its values, and leaves odometry out of the bag topics.
  const auto stlucia = dir / "config_stlucia_vo.txt";
  std::ofstream(stlucia) << "[general]\ntopic_root=stlucia\n[ratslam]\ntemplate_x_size=60\n"
                            "[visual_odometry]\nvtrans_image_x_min=195\nvtrans_image_x_max=475\n"
                            "vtrans_image_y_min=270\nvtrans_image_y_max=430\n"
                            "vrot_image_x_min=195\nvrot_image_x_max=475\nvrot_image_y_min=75\n"
                            "vrot_image_y_max=240\ncamera_fov_deg=53\ncamera_hz=10\n"
                            "vtrans_scaling=1000\nvtrans_max=20\n";
  StatusOr<ImportedConfig> slvo = ImportOpenRatslamIni(stlucia.string());
  ASSERT_TRUE(slvo.ok()) << slvo.status().message();
  const sensors::VisualOdometryOptions& vo = slvo->options.visual_odometry;
  EXPECT_TRUE(vo.enabled);
  EXPECT_EQ(vo.model, "openratslam");
  EXPECT_EQ(vo.max_shift_px, 39);
  EXPECT_EQ(vo.translation_left_px, 195);
  EXPECT_EQ(vo.translation_right_px, 475);
  EXPECT_EQ(vo.translation_top_px, 270);
  EXPECT_EQ(vo.translation_bottom_px, 430);
  EXPECT_EQ(vo.rotation_left_px, 195);
  EXPECT_EQ(vo.rotation_right_px, 475);
  EXPECT_EQ(vo.rotation_top_px, 75);
  EXPECT_EQ(vo.rotation_bottom_px, 240);
  EXPECT_DOUBLE_EQ(vo.field_of_view_rad, 53 * M_PI / 180);
  EXPECT_EQ(vo.camera_hz, 10.0);
  EXPECT_EQ(vo.translation_scaling, 1000.0);
  EXPECT_EQ(vo.max_speed_m_per_s, 20.0);
  EXPECT_EQ(slvo->options.bag.image_topic, "/stlucia/camera/image");
  EXPECT_EQ(slvo->options.bag.odometry_topic, "");

  // A value our checks refuse names the INI line; a default they refuse says it was one.
  const auto bad = dir / "bad.ini";
  std::ofstream(bad) << "[ratslam]\ntemplate_x_size=60\npc_w_e_dim=4\n";
  Status s = ImportOpenRatslamIni(bad.string()).status();
  EXPECT_NE(s.message().find("bad.ini:3: pc_w_e_dim = 4"), std::string::npos) << s.message();
  std::ofstream(bad) << "[ratslam]\nvt_match_threshold=0.1\n";
  s = ImportOpenRatslamIni(bad.string()).status();
  EXPECT_NE(s.message().find("template_x_size not set (OpenRatSLAM's default 1)"),
            std::string::npos)
      << s.message();
}

TEST(ConfigTest, AnOpenRatslamIniPassedAsConfigSaysHowToConvertIt) {
  const auto path = TestScratch().path() / "given_as_config.ini";
  // Keys OpenRatSLAM uses, in a section of ours: the INI's [ratslam] section is found first.
  std::ofstream(path) << "# from an OpenRatSLAM data set\n[ratslam]\nvt_match_threshold=0.085\n"
                         "pc_dim_xy=30\n";
  StatusOr<fusion::PipelineOptions> loaded = LoadConfigFile(path.string());
  ASSERT_FALSE(loaded.ok());
  const std::string& m = loaded.status().message();
  EXPECT_NE(m.find("is an OpenRatSLAM configuration (line 2: section [ratslam])"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("ratslam import-openratslam " + path.string()), std::string::npos) << m;
  // A key alone gives it away too.
  std::ofstream(path) << "topic_root = irat_red\n";
  loaded = LoadConfigFile(path.string());
  ASSERT_FALSE(loaded.ok());
  EXPECT_NE(loaded.status().message().find("line 1: key topic_root"), std::string::npos)
      << loaded.status().message();
  // A typo in one of our files is not mistaken for one.
  std::ofstream(path) << "[wifi]\nmatch_treshold = 0.5\n";
  loaded = LoadConfigFile(path.string());
  ASSERT_FALSE(loaded.ok());
  EXPECT_EQ(loaded.status().message().find("OpenRatSLAM"), std::string::npos)
      << loaded.status().message();
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace ratslam::io

namespace ratslam::io {
namespace {

// docs/config.md's key tables are made from the field lists that read and print configurations,
// so they cannot drift apart (tests/generated_block.h).
TEST(ConfigReferenceTest, DocsCarryTheCurrentKeyTables) {
  const std::string tables = ConfigReferenceMarkdown();
  e2e::ExpectGeneratedBlock("docs/config.md", "config reference", tables);
  // Every key of the default configuration has a row (a known key, a known answer).
  EXPECT_NE(tables.find("| `recognise_views` | `false` |"), std::string::npos);
  EXPECT_NE(tables.find("### [pose_cells]"), std::string::npos);
}

}  // namespace
}  // namespace ratslam::io
