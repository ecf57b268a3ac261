// The configuration of `ratslam demo` (the fused front end on a simulated world) and the one
// tuned for the built-in synthetic camera loop (`ratslam synthesize`). The same values are
// committed as configs/demo.toml and configs/synthetic.toml (a test keeps them equal).
#ifndef RATSLAM_APPS_DEMO_CONFIG_H_
#define RATSLAM_APPS_DEMO_CONFIG_H_

#include <string>

#include "dataset/synthetic_dataset.h"
#include "fusion/replay_pipeline.h"

namespace ratslam::apps {

// Camera (12x9) + Wi-Fi + compass with the b_out rule, for the simulated worlds.
fusion::PipelineOptions DemoPipelineOptions();
// The built-in world the demo simulates.
std::string DemoWorldName();
// The classic camera matcher on the synthetic pillar loop.
fusion::PipelineOptions SyntheticPipelineOptions();
dataset::SyntheticOptions DemoSyntheticOptions();

}  // namespace ratslam::apps

#endif  // RATSLAM_APPS_DEMO_CONFIG_H_
