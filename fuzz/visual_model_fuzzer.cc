// FABMAP visual model files: errors name the file; a model that decodes is accepted or refused
// cleanly by FABMAP, and then maps and localises.
#include <string>

#include "common/random.h"
#include "fusion/fabmap/fabmap.h"
#include "fusion/fabmap/visual_model.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  std::vector<std::string> seeds;
  for (int words : {8, 16}) {
    Random data(9 + words);
    fabmap::DescriptorSet descriptors;
    descriptors.kind = fabmap::DescriptorKind::kOrb;
    descriptors.length = 32;
    descriptors.count = 64;
    for (int i = 0; i < 64 * 32; ++i) descriptors.binary.push_back(data.NextU64() & 0xFF);
    fabmap::VocabularyOptions vocabulary_options;
    vocabulary_options.words = words;
    fabmap::TrainedVisualModel model;
    model.vocabulary = *fabmap::Vocabulary::Train(descriptors, vocabulary_options);
    for (int i = 0; i < 12; ++i) {
      fabmap::Observation o;
      for (fabmap::WordId q = 0; q < static_cast<fabmap::WordId>(words); ++q) {
        if (data.Uniform() < 0.3) o.push_back(q);
      }
      model.model.samples.push_back(o);
    }
    model.model.tree = *fabmap::LearnChowLiuTree(model.model.samples, words);
    seeds.push_back(fabmap::EncodeVisualModel(model));
  }
  return seeds;
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  auto decoded = fabmap::DecodeVisualModel(std::string(reinterpret_cast<const char*>(data), size),
                                           "model.bin");
  if (!decoded.ok()) {
    if (decoded.status().message().rfind("model.bin", 0) != 0) {
      fuzz::InvariantFailed("error does not name the file: " + decoded.status().message());
    }
    return 0;
  }
  fabmap::DetectorBlock block;
  block.count = decoded->vocabulary.size();
  auto model =
      fabmap::FabmapModel::Create(decoded->model.tree, {block}, decoded->model.samples, {});
  if (!model.ok()) return 0;
  const fabmap::WordId words = static_cast<fabmap::WordId>(decoded->vocabulary.size());
  if (words == 0) return 0;
  (void)model->AddPlace({0, words - 1});
  (void)model->AddPlace({words / 2});
  (void)model->Localise({0, words / 2});
  return 0;
}
