// OpenRatSLAM INI files: errors name the file; an imported config is valid and round-trips
// through our TOML.
#include <string>

#include "fuzz/fuzz_support.h"
#include "io/config.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  return {
      "[general]\ntopic_root=irat_red\n\n[ratslam]\nvt_match_threshold=0.085\npc_dim_xy=30\n"
      "pc_cell_x_size=0.015\nexp_loops=20\nvt_active_decay = 1.5 ; comment\nvt_panoramic=1\n"
      "[draw]\nenable=1\n",
      "[ratslam]\nimage_crop_x_min=40\nimage_crop_x_max=600\ntemplate_x_size=60\n"
      "template_y_size=10\nvt_shift_match=5\nvt_step_match=1\npc_dim_th=36\npc_w_e_dim=7\n"
      "pc_w_i_dim=5\npc_global_inhib=0.00002\nexp_correction=0.5\nvt_normalisation=0.4\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  const std::string path = fuzz::WriteScratchFile("in.ini", data, size);
  StatusOr<io::ImportedConfig> imported = io::ImportOpenRatslamIni(path);
  if (!imported.ok()) {
    if (imported.status().message().rfind(path, 0) != 0) {
      fuzz::InvariantFailed("error does not name the file: " + imported.status().message());
    }
    return 0;
  }
  std::string error;
  if (!imported->options.IsValid(&error))
    fuzz::InvariantFailed("imported invalid options: " + error);
  const std::string printed = io::PrintConfig(imported->options);
  StatusOr<fusion::PipelineOptions> back = io::ParseConfig(printed, "printed.toml");
  if (!back.ok() || io::PrintConfig(*back) != printed)
    fuzz::InvariantFailed("TOML round trip failed");
  return 0;
}
