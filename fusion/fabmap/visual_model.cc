#include "fusion/fabmap/visual_model.h"

#include <cmath>

#include "common/byte_buffer.h"

namespace ratslam::fabmap {

bool VisualModelOptions::IsValid(std::string* error) const {
  return schema::CheckFields(*this, error);
}

StatusOr<TrainedVisualModel> TrainVisualModel(const std::vector<std::string>& images,
                                              const FeatureOptions& features,
                                              const VocabularyOptions& vocabulary,
                                              const ChowLiuOptions& chow_liu, ImageLoader& loader,
                                              const std::function<void(size_t, size_t)>& progress) {
  if (images.empty()) return Status::Error("visual model: no training images");
  std::vector<DescriptorSet> per_image;
  DescriptorSet all;
  for (size_t i = 0; i < images.size(); ++i) {
    auto image = loader.Load(images[i]);
    if (!image.ok()) return image.status();
    auto d = ExtractFeatures(*image, features);
    if (!d.ok()) return d.status().WithContext(images[i]);
    RATSLAM_RETURN_IF_ERROR(all.Append(*d));
    per_image.push_back(*std::move(d));
    if (progress) progress(i + 1, images.size());
  }
  TrainedVisualModel trained;
  trained.features = features;
  auto v = Vocabulary::Train(all, vocabulary);
  if (!v.ok()) return v.status();
  trained.vocabulary = *std::move(v);
  for (const DescriptorSet& d : per_image) {
    trained.model.samples.push_back(trained.vocabulary.Quantise(d));
  }
  auto tree = LearnChowLiuTree(trained.model.samples, trained.vocabulary.size(), chow_liu);
  if (!tree.ok()) return tree.status();
  trained.model.tree = *std::move(tree);
  return trained;
}

StatusOr<Observation> ImageWords(const TrainedVisualModel& model, const GrayImage& image) {
  auto d = ExtractFeatures(image, model.features);
  if (!d.ok()) return d.status();
  return model.vocabulary.Quantise(*d);
}

namespace {
constexpr uint32_t kModelMagic = 0x4d565252;  // "RRVM"
constexpr uint32_t kModelVersion = 1;
}  // namespace

std::string EncodeVisualModel(const TrainedVisualModel& m) {
  ByteWriter w;
  w.Pod(kModelMagic);
  w.Pod(kModelVersion);
  w.Pod<uint8_t>(m.features.descriptor == DescriptorKind::kOrb ? 0 : 1);
  w.Pod<int32_t>(m.features.max_features);
  w.Pod<int32_t>(m.features.fast_threshold);
  w.String(m.vocabulary.Encode());
  const ChowLiuTree& t = m.model.tree;
  w.PodVector(t.parent);
  w.PodVector(t.marginal);
  w.PodVector(t.on_given_parent_on);
  w.PodVector(t.on_given_parent_off);
  w.Count(m.model.samples.size());
  for (const Observation& o : m.model.samples) w.PodVector(o);
  return std::move(w.bytes());
}

StatusOr<TrainedVisualModel> DecodeVisualModel(const std::string& bytes,
                                               const std::string& source) {
  ByteReader r(bytes, source);
  uint32_t magic = 0, version = 0;
  uint8_t kind = 0;
  std::string vocabulary_bytes;
  TrainedVisualModel m;
  ChowLiuTree& t = m.model.tree;
  size_t samples = 0;
  bool ok = r.Pod(&magic) && (magic == kModelMagic || r.Fail("not a visual model file")) &&
            r.Pod(&version) && (version == kModelVersion || r.Fail("unsupported version")) &&
            r.Pod(&kind) && (kind <= 1 || r.Fail("unknown descriptor")) &&
            r.Pod(&m.features.max_features) && r.Pod(&m.features.fast_threshold) &&
            r.String(&vocabulary_bytes) && r.PodVector(&t.parent) && r.PodVector(&t.marginal) &&
            r.PodVector(&t.on_given_parent_on) && r.PodVector(&t.on_given_parent_off) &&
            r.Count(8, &samples);
  for (size_t i = 0; ok && i < samples; ++i) {
    Observation o;
    ok = r.PodVector(&o);
    m.model.samples.push_back(std::move(o));
  }
  if (!(ok && (r.AtEnd() || r.Fail("trailing bytes")))) return Status::Error(r.error());
  m.features.descriptor = kind == 0 ? DescriptorKind::kOrb : DescriptorKind::kSift;
  std::string error;
  if (!m.features.IsValid(&error)) return Status::Error(source + ": " + error);
  auto v = Vocabulary::Decode(vocabulary_bytes, source + " (vocabulary)");
  if (!v.ok()) return v.status();
  m.vocabulary = *std::move(v);
  const size_t n = m.vocabulary.size();
  if (t.parent.size() != n || t.marginal.size() != n || t.on_given_parent_on.size() != n ||
      t.on_given_parent_off.size() != n || m.vocabulary.kind() != m.features.descriptor) {
    return Status::Error(source + ": the tree does not match the vocabulary");
  }
  for (size_t q = 0; q < n; ++q) {
    const double p[3] = {t.marginal[q], t.on_given_parent_on[q], t.on_given_parent_off[q]};
    for (double x : p) {
      if (!(x > 0.0 && x < 1.0))
        return Status::Error(source + ": a tree probability is not in (0, 1)");
    }
    if (t.parent[q] != ChowLiuTree::kNoParent && t.parent[q] >= n) {
      return Status::Error(source + ": a tree parent is outside the vocabulary");
    }
  }
  for (size_t i = 0; i < m.model.samples.size(); ++i) {
    RATSLAM_RETURN_IF_ERROR(NormaliseObservation(&m.model.samples[i], static_cast<uint32_t>(n),
                                                 source + ": sample " + std::to_string(i)));
  }
  if (m.model.samples.empty()) return Status::Error(source + ": no unknown-world samples");
  return m;
}

}  // namespace ratslam::fabmap
