// Descriptor files (.npy or CSV; the first byte chooses): any bytes parse to a matrix or an error
// naming the file; an accepted matrix has rows * cols finite values, survives a write and read
// back bit for bit, and drives the descriptor front end over a data set of as many images (the
// same state as feeding the rows one by one), whose state then round-trips.
#include <cmath>
#include <cstring>
#include <string>

#include "dataset/descriptor_file.h"
#include "fusion/front_end.h"
#include "fuzz/fuzz_support.h"

namespace ratslam::fuzz {

std::vector<std::string> FuzzSeeds() {
  dataset::DescriptorMatrix m{3, 4, {1, 2, 3, 4, 0.5f, -1, 2, 0, 1, 2, 3, 4.5f}};
  const std::string path = (Scratch().path() / "seed.npy").string();
  (void)dataset::WriteDescriptorNpy(m, path);
  std::string npy = "n";
  {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    char buffer[4096];
    size_t n = 0;
    while (f && (n = std::fread(buffer, 1, sizeof buffer, f)) > 0) npy.append(buffer, n);
    if (f) std::fclose(f);
  }
  return {npy, "c1,2,3\n4,5,6\n1,2,3.5\n", "cd0,d1\n0.25,-1e-3\n7,8\n"};
}

}  // namespace ratslam::fuzz

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace ratslam;
  if (size == 0) return 0;
  const bool npy = data[0] == 'n';
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  StatusOr<dataset::DescriptorMatrix> m = dataset::ParseDescriptors(bytes, "fuzz.desc", npy);
  if (!m.ok()) {
    if (m.status().message().find("fuzz.desc") == std::string::npos) {
      fuzz::InvariantFailed("an error that does not name the file");
    }
    return 0;
  }
  if (m->rows == 0 || m->cols == 0 || m->values.size() != m->rows * m->cols) {
    fuzz::InvariantFailed("matrix size");
  }
  for (float v : m->values) {
    if (!std::isfinite(v)) fuzz::InvariantFailed("a non-finite value was accepted");
  }
  const std::string path = (fuzz::Scratch().path() / "round.npy").string();
  if (!dataset::WriteDescriptorNpy(*m, path).ok()) fuzz::InvariantFailed("write failed");
  StatusOr<dataset::DescriptorMatrix> back = dataset::ReadDescriptorFile(path);
  if (!back.ok() || back->rows != m->rows || back->cols != m->cols ||
      std::memcmp(back->values.data(), m->values.data(), 4 * m->values.size()) != 0) {
    fuzz::InvariantFailed("npy round trip");
  }
  if (m->rows > 200 || m->cols > 64) return 0;  // the front end on small matrices only
  dataset::Dataset dataset;
  dataset.name = "fuzz";
  for (size_t i = 0; i < m->rows; ++i) dataset.images.push_back({static_cast<double>(i), "x", 0});
  auto table = fusion::DescriptorTable::Make(*m, dataset, "fuzz.desc");
  if (!table.ok()) return 0;  // a zero row
  fusion::FrontEndSettings settings;
  settings.front_end.kind = fusion::FrontEndKind::kDescriptors;
  settings.descriptors.recency_s = 1.5;
  fusion::FrontEndResources resources;
  resources.descriptors = *table;
  auto front_end = fusion::CreateFrontEnd(settings, resources);
  for (const ImageRow& image : dataset.images) {
    auto d = front_end->OnImage(image.time_s, GrayImage());
    if (!d.ok() || !d.value()) fuzz::InvariantFailed("a known image was refused");
    if (d.value()->view.template_id > front_end->size()) fuzz::InvariantFailed("template id");
  }
  // Fed one by one without the table, the same rows make the same state.
  auto fed = fusion::CreateFrontEnd(settings);
  for (size_t i = 0; i < m->rows; ++i) {
    const std::vector<float> row(m->values.begin() + static_cast<ptrdiff_t>(i * m->cols),
                                 m->values.begin() + static_cast<ptrdiff_t>((i + 1) * m->cols));
    if (!fed->OnDescriptor(dataset.images[i].time_s, row).ok()) {
      fuzz::InvariantFailed("a fed row was refused");
    }
  }
  if (fed->EncodeState() != front_end->EncodeState()) fuzz::InvariantFailed("fed state differs");
  auto copy = fusion::CreateFrontEnd(settings, resources);
  if (!copy->DecodeState(front_end->EncodeState()).ok() ||
      copy->EncodeState() != front_end->EncodeState()) {
    fuzz::InvariantFailed("state round trip");
  }
  return 0;
}
