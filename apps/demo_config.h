// The configuration of `ratslam demo`, tuned for the built-in synthetic data set. The same
// values are committed as configs/demo.toml (a test keeps the two equal).
#ifndef RATSLAM_APPS_DEMO_CONFIG_H_
#define RATSLAM_APPS_DEMO_CONFIG_H_

#include "fusion/replay_pipeline.h"
#include "sensors/dataset/synthetic_dataset.h"

namespace ratslam {

PipelineOptions DemoPipelineOptions();
SyntheticOptions DemoSyntheticOptions();

}  // namespace ratslam

#endif  // RATSLAM_APPS_DEMO_CONFIG_H_
