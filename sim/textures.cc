#include "sim/textures.h"

#include <algorithm>
#include <cmath>

#include "common/random.h"

namespace ratslam::sim {

namespace {

const char* const kKinds[] = {"plaster", "brick", "stripes", "checker", "tiles", "wood",
                              "posters", "door",  "noise",   "person",  "floor", "ceiling"};

bool Split(const std::string& name, std::string* kind, int* variant) {
  const auto colon = name.find(':');
  *kind = name.substr(0, colon);
  *variant = 0;
  if (colon != std::string::npos) {
    const std::string v = name.substr(colon + 1);
    if (v.empty() || v.size() > 6 || !std::all_of(v.begin(), v.end(), ::isdigit)) return false;
    *variant = std::stoi(v);
  }
  return std::find(std::begin(kKinds), std::end(kKinds), *kind) != std::end(kKinds);
}

uint64_t Hash(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}

// Smooth value noise in [0, 1] with `cells` cells across, wrapping (the texture tiles).
std::vector<double> ValueNoise(int size, int cells, Random* random) {
  std::vector<double> grid(static_cast<size_t>(cells) * cells);
  for (double& g : grid) g = random->Uniform();
  std::vector<double> out(static_cast<size_t>(size) * size);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double gx = static_cast<double>(x) * cells / size,
                   gy = static_cast<double>(y) * cells / size;
      const int x0 = static_cast<int>(gx), y0 = static_cast<int>(gy);
      const double fx = gx - x0, fy = gy - y0;
      const double sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
      auto at = [&](int i, int j) {
        return grid[static_cast<size_t>(j % cells) * cells + i % cells];
      };
      const double top = at(x0, y0) * (1 - sx) + at(x0 + 1, y0) * sx;
      const double bottom = at(x0, y0 + 1) * (1 - sx) + at(x0 + 1, y0 + 1) * sx;
      out[static_cast<size_t>(y) * size + x] = top * (1 - sy) + bottom * sy;
    }
  }
  return out;
}

}  // namespace

bool IsTextureName(const std::string& name) {
  std::string kind;
  int variant = 0;
  return Split(name, &kind, &variant);
}

std::vector<uint8_t> MakeTexture(const std::string& name, int size) {
  std::string kind;
  int variant = 0;
  Split(name, &kind, &variant);
  Random random(Hash(name));
  std::vector<double> v(static_cast<size_t>(size) * size, 0.6);
  auto px = [&](int x, int y) -> double& { return v[static_cast<size_t>(y) * size + x]; };
  const std::vector<double> grain = ValueNoise(size, 8, &random);
  if (kind == "plaster" || kind == "noise" || kind == "floor" || kind == "ceiling") {
    const int cells = kind == "noise" ? 8 : 4;
    const std::vector<double> n = ValueNoise(size, cells, &random);
    const double base = kind == "floor"     ? 0.35
                        : kind == "ceiling" ? 0.85
                                            : random.Uniform(0.45, 0.75);
    const double amplitude = kind == "noise" ? 0.5 : 0.12;
    for (size_t i = 0; i < v.size(); ++i) v[i] = base + amplitude * (n[i] - 0.5);
  } else if (kind == "brick") {
    const int rows = 8, per_row = 4;
    const int bh = size / rows, bw = size / per_row;
    std::vector<double> shade(rows * (per_row + 1));
    for (double& s : shade) s = random.Uniform(0.35, 0.6);
    for (int y = 0; y < size; ++y) {
      const int row = y / bh;
      const int offset = (row % 2) * bw / 2;
      for (int x = 0; x < size; ++x) {
        const int xs = (x + offset) % size;
        const bool mortar = y % bh == 0 || xs % bw == 0;
        px(x, y) = mortar ? 0.85 : shade[row * (per_row + 1) + xs / bw];
      }
    }
  } else if (kind == "stripes") {
    int x = 0;
    while (x < size) {
      const int w = 2 + static_cast<int>(random.Uniform() * size / 4);
      const double g = random.Uniform(0.1, 0.95);
      for (int i = x; i < std::min(size, x + w); ++i) {
        for (int y = 0; y < size; ++y) px(i, y) = g;
      }
      x += w;
    }
  } else if (kind == "checker") {
    const int n = 2 + variant % 4;
    const double a = random.Uniform(0.1, 0.4), b = random.Uniform(0.6, 0.95);
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) px(x, y) = ((x * n / size + y * n / size) % 2) ? a : b;
    }
  } else if (kind == "tiles") {
    const int n = 4;
    const double g = random.Uniform(0.5, 0.8);
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x)
        px(x, y) = (x % (size / n) < 2 || y % (size / n) < 2) ? 0.25 : g;
    }
  } else if (kind == "wood") {
    const double base = random.Uniform(0.3, 0.5);
    const double frequency = random.Uniform(6, 14);
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        px(x, y) =
            base + 0.12 * std::sin(2 * M_PI * (y * frequency / size + 0.8 * grain[y * size + x]));
      }
    }
  } else if (kind == "posters") {
    for (double& x : v) x = random.Uniform(0.55, 0.6);
    const int count = 2 + static_cast<int>(random.Uniform() * 3);
    for (int k = 0; k < count; ++k) {
      const int w = size / 6 + static_cast<int>(random.Uniform() * size / 3);
      const int h = size / 5 + static_cast<int>(random.Uniform() * size / 3);
      const int x0 = static_cast<int>(random.Uniform() * (size - w));
      const int y0 = size / 8 + static_cast<int>(random.Uniform() * (size / 2 - h / 2));
      const double g =
          random.Uniform() < 0.5 ? random.Uniform(0.05, 0.3) : random.Uniform(0.8, 1.0);
      for (int y = y0; y < std::min(size, y0 + h); ++y) {
        for (int x = x0; x < x0 + w; ++x) px(x, y) = g;
      }
    }
  } else if (kind == "door") {
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const bool frame = x < size / 10 || x >= size - size / 10 || y < size / 12;
        px(x, y) = frame ? 0.15 : 0.45 + 0.05 * grain[y * size + x];
      }
    }
  } else if (kind == "person") {
    for (int y = 0; y < size; ++y) {
      for (int x = 0; x < size; ++x) {
        const double dx = (x - size / 2.0) / (size / 2.0);
        const bool head = y < size / 6 && std::abs(dx) < 0.25;
        const bool body = y >= size / 6 && std::abs(dx) < 0.45;
        px(x, y) = head ? 0.7 : body ? 0.12 + 0.1 * grain[y * size + x] : 0.5;
      }
    }
  }
  // Fine grain everywhere, so that no surface is perfectly flat.
  std::vector<uint8_t> out(v.size());
  for (size_t i = 0; i < v.size(); ++i) {
    const double g = std::clamp(v[i] + 0.04 * (grain[i] - 0.5), 0.0, 1.0);
    out[i] = static_cast<uint8_t>(std::lround(g * 255.0));
  }
  return out;
}

}  // namespace ratslam::sim
