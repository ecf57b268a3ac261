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

namespace {

// The file, field by field in file order: Describe below both writes and reads it (the archives
// of common/byte_buffer.h), so the two cannot disagree.
struct VisualModelFile {
  uint32_t magic = kModelMagic;
  uint32_t version = kModelVersion;
  uint8_t descriptor = 0;  // 0 ORB, 1 SIFT
  int32_t max_features = 0;
  int32_t fast_threshold = 0;
  std::string vocabulary;  // Vocabulary::Encode's bytes
  ChowLiuTree tree;
  std::vector<Observation> samples;
};

}  // namespace
}  // namespace ratslam::fabmap

namespace ratslam {
// Found by the archives (namespace ratslam) for the unknown-world samples.
template <typename A>
bool Describe(A& a, fabmap::Observation& o) {
  return a(o);
}
template <typename A>
bool Describe(A& a, fabmap::VisualModelFile& f) {
  return a(f.magic) && a.Check(f.magic == fabmap::kModelMagic, "not a visual model file") &&
         a(f.version) && a.Check(f.version == fabmap::kModelVersion, "unsupported version") &&
         a(f.descriptor) && a.Check(f.descriptor <= 1, "unknown descriptor") && a(f.max_features) &&
         a(f.fast_threshold) && a(f.vocabulary) && a(f.tree.parent) && a(f.tree.marginal) &&
         a(f.tree.on_given_parent_on) && a(f.tree.on_given_parent_off) && a.Objects(f.samples, 8);
}
}  // namespace ratslam

namespace ratslam::fabmap {

std::string EncodeVisualModel(const TrainedVisualModel& m) {
  VisualModelFile file;
  file.descriptor = m.features.descriptor == DescriptorKind::kOrb ? 0 : 1;
  file.max_features = m.features.max_features;
  file.fast_threshold = m.features.fast_threshold;
  file.vocabulary = m.vocabulary.Encode();
  file.tree = m.model.tree;
  file.samples = m.model.samples;
  ByteWriter w;
  EncodeArchive archive(w, kModelVersion);
  Describe(archive, file);
  return std::move(w.bytes());
}

StatusOr<TrainedVisualModel> DecodeVisualModel(const std::string& bytes,
                                               const std::string& source) {
  ByteReader r(bytes, source);
  VisualModelFile file;
  DecodeArchive archive(r, kModelVersion);
  if (!(Describe(archive, file) && (r.AtEnd() || r.Fail("trailing bytes")))) {
    return Status::Error(r.error());
  }
  TrainedVisualModel m;
  m.features.descriptor = file.descriptor == 0 ? DescriptorKind::kOrb : DescriptorKind::kSift;
  m.features.max_features = file.max_features;
  m.features.fast_threshold = file.fast_threshold;
  m.model.tree = std::move(file.tree);
  m.model.samples = std::move(file.samples);
  ChowLiuTree& t = m.model.tree;
  const std::string vocabulary_bytes = std::move(file.vocabulary);
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
