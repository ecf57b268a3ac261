// Shared by the coverage-guided fuzz harnesses (libFuzzer, built with clang by
// scripts/fuzz.sh) and by their replay drivers (any compiler; ctest runs every committed
// regression input and every seed through them).
//
// Each harness defines LLVMFuzzerTestOneInput and FuzzSeeds(): small valid inputs that start
// the corpus, generated in code so that no data set is copied into the repository.
#ifndef RATSLAM_FUZZ_FUZZ_SUPPORT_H_
#define RATSLAM_FUZZ_FUZZ_SUPPORT_H_

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "common/checksum.h"
#include "common/scratch_dir.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace ratslam::fuzz {

// `bytes` with their last four bytes replaced by the CRC-32C of the rest (common/checksum.h): a
// fuzzer's mutations then reach the decoder behind a file's checksum instead of stopping at it.
inline std::string WithMatchingChecksum(std::string bytes) {
  if (bytes.size() < 4) return bytes;
  bytes.resize(bytes.size() - 4);
  AppendChecksum(&bytes);
  return bytes;
}

// Runs `use` on the input as it is (formats from before checksums have none) and, when it
// differs, behind a matching checksum (WithMatchingChecksum).
template <typename Use>
int AsIsAndChecksummed(const uint8_t* data, size_t size, Use use) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string checked = WithMatchingChecksum(bytes);
  use(bytes);
  if (checked != bytes) use(checked);
  return 0;
}

// Valid example inputs for this harness (the driver writes them with --seeds DIR).
std::vector<std::string> FuzzSeeds();

// One scratch folder per process, for readers that take a path.
inline const ScratchDir& Scratch() {
  static const ScratchDir dir("ratslam_fuzz");
  return dir;
}

// Writes `size` bytes to `name` in the scratch folder; returns its path.
std::string WriteScratchFile(const std::string& name, const uint8_t* data, size_t size);

// Splits an input into parts at a separator line; a data set's files are fuzzed as one input.
std::vector<std::string> SplitParts(const uint8_t* data, size_t size, const std::string& separator);

// A fresh folder `name` in the scratch folder holding parts[i] as files[i] (as many as both
// have; a file may be in a subfolder); returns its path. Data sets and run folders are fuzzed
// as one input this way.
std::string WriteScratchFolder(const std::string& name, const std::vector<std::string>& parts,
                               const std::vector<std::string>& files);

// A failed invariant: prints the message and aborts, which the fuzzer reports as a crash.
[[noreturn]] void InvariantFailed(const std::string& message);

}  // namespace ratslam::fuzz

#endif  // RATSLAM_FUZZ_FUZZ_SUPPORT_H_
