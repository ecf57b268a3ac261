#include "render/image.h"

#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <system_error>
#include <thread>
#include <vector>

#include "common/file_util.h"

namespace ratslam::render {

namespace {

// PNG (ISO/IEC 15948) written here rather than through OpenCV: rows filtered and deflated in
// bands of kBandRows on all cores. Each band is a raw deflate stream ending on a full flush (the
// last one finishing), so the bands concatenate into one zlib stream; the band size is fixed, so
// the file's bytes do not depend on the number of cores. zlib level 1 with run-length matching
// and the Sub filter, as OpenCV's fastest settings.
constexpr int kBandRows = 128;

void PutU32(uint32_t v, std::string* out) {
  const char bytes[4] = {static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                         static_cast<char>(v >> 8), static_cast<char>(v)};
  out->append(bytes, 4);
}

void AppendChunk(const char* type, const std::string& data, std::string* png) {
  PutU32(static_cast<uint32_t>(data.size()), png);
  const size_t start = png->size();
  png->append(type, 4);
  png->append(data);
  const auto* bytes = reinterpret_cast<const Bytef*>(png->data() + start);
  PutU32(static_cast<uint32_t>(crc32(0, bytes, static_cast<uInt>(data.size() + 4))), png);
}

struct Band {
  std::string deflated;
  uint32_t adler = 1;
  size_t filtered_bytes = 0;
  bool ok = false;
};

// Filters rows [row0, row1) (Sub filter; `channels` of the RGBA pixels) and deflates them.
void EncodeBand(const RgbaImage& image, int channels, int row0, int row1, bool last, Band* band) {
  const size_t w = static_cast<size_t>(image.width);
  const size_t row_bytes = 1 + w * channels;
  std::vector<uint8_t> filtered(row_bytes * static_cast<size_t>(row1 - row0));
  for (int y = row0; y < row1; ++y) {
    uint8_t* out = &filtered[row_bytes * static_cast<size_t>(y - row0)];
    const uint8_t* in = &image.pixels[w * 4 * static_cast<size_t>(y)];
    *out++ = 1;  // Sub: each byte minus the same channel of the pixel to its left
    uint8_t left[4] = {0, 0, 0, 0};
    for (size_t x = 0; x < w; ++x, in += 4) {
      for (int c = 0; c < channels; ++c) {
        *out++ = static_cast<uint8_t>(in[c] - left[c]);
        left[c] = in[c];
      }
    }
  }
  band->filtered_bytes = filtered.size();
  band->adler =
      static_cast<uint32_t>(adler32(1, filtered.data(), static_cast<uInt>(filtered.size())));
  z_stream z{};
  if (deflateInit2(&z, Z_BEST_SPEED, Z_DEFLATED, -15, 8, Z_RLE) != Z_OK) return;
  band->deflated.resize(deflateBound(&z, filtered.size()) + 16);
  z.next_in = filtered.data();
  z.avail_in = static_cast<uInt>(filtered.size());
  z.next_out = reinterpret_cast<Bytef*>(band->deflated.data());
  z.avail_out = static_cast<uInt>(band->deflated.size());
  const int result = deflate(&z, last ? Z_FINISH : Z_FULL_FLUSH);
  band->ok = last ? result == Z_STREAM_END : (result == Z_OK && z.avail_in == 0);
  band->deflated.resize(z.total_out);
  deflateEnd(&z);
}

}  // namespace

Status WritePng(const RgbaImage& image, const std::string& path) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<size_t>(image.width) * image.height * 4) {
    return Status::Error(path + ": empty or inconsistent image");
  }
  // An opaque image (all our figures) goes out as RGB: a quarter less to filter and compress.
  bool opaque = true;
  for (size_t i = 3; i < image.pixels.size() && opaque; i += 4) opaque = image.pixels[i] == 255;
  const int channels = opaque ? 3 : 4;
  const int bands = (image.height + kBandRows - 1) / kBandRows;
  std::vector<Band> band(static_cast<size_t>(bands));
  auto encode = [&](int b) {
    EncodeBand(image, channels, b * kBandRows, std::min(image.height, (b + 1) * kBandRows),
               b == bands - 1, &band[static_cast<size_t>(b)]);
  };
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int b = next++; b < bands; b = next++) encode(b);
  };
  std::vector<std::thread> threads;
#if defined(RATSLAM_SANITIZED_BUILD)
  // Under sanitizers this thread encodes every band: a band thread joined just before the
  // process exits can still be in the kernel's teardown when LeakSanitizer's tracer stops the
  // world, and the tracer then crashes ("Tracer caught signal 11": an `evaluate` writing its
  // figures, in CI under load), as it did with llvmpipe's and OpenCV's worker threads.
  const int extra = 0;
#else
  const int extra = std::min<int>(bands, static_cast<int>(std::thread::hardware_concurrency())) - 1;
#endif
  try {
    for (int t = 0; t < extra; ++t) threads.emplace_back(worker);
  } catch (const std::system_error&) {
    // No threads to be had: this thread encodes every band.
  }
  worker();
  for (std::thread& t : threads) t.join();

  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  PutU32(static_cast<uint32_t>(image.width), &header);
  PutU32(static_cast<uint32_t>(image.height), &header);
  header += static_cast<char>(8);               // bits per channel
  header += static_cast<char>(opaque ? 2 : 6);  // colour type: RGB or RGBA
  header.append(3, '\0');                       // deflate, adaptive filters, no interlace
  AppendChunk("IHDR", header, &png);
  std::string data("\x78\x01", 2);  // zlib header: deflate, 32 KiB window, fastest
  uLong adler = 1;
  for (const Band& b : band) {
    if (!b.ok) return Status::Error(path + ": cannot compress PNG");
    data += b.deflated;
    adler = adler32_combine(adler, b.adler, static_cast<z_off_t>(b.filtered_bytes));
  }
  PutU32(static_cast<uint32_t>(adler), &data);
  AppendChunk("IDAT", data, &png);
  AppendChunk("IEND", "", &png);
  // Written checked and renamed into place: a full disk is an error, never a 0-byte PNG.
  return WriteFileAtomically(path, png, /*flush_to_disk=*/false);
}

StatusOr<RgbaImage> ReadPng(const std::string& path) {
  if (!PathExists(path)) return Status::Error(path + ": file missing");
  cv::Mat bgra = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (bgra.empty()) return Status::Error(path + ": cannot read image");
  cv::Mat rgba;
  if (bgra.channels() == 4) {
    cv::cvtColor(bgra, rgba, cv::COLOR_BGRA2RGBA);
  } else if (bgra.channels() == 3) {
    cv::cvtColor(bgra, rgba, cv::COLOR_BGR2RGBA);
  } else {
    cv::cvtColor(bgra, rgba, cv::COLOR_GRAY2RGBA);
  }
  RgbaImage image;
  image.width = rgba.cols;
  image.height = rgba.rows;
  image.pixels.assign(rgba.data, rgba.data + rgba.total() * 4);
  return image;
}

namespace {
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// FONT_HERSHEY_SIMPLEX is about 22 px high (cap height) at scale 1.
double FontScale(float height_px) { return height_px / 22.0; }
int FontThickness(float height_px) {
  return std::max(1, static_cast<int>(std::lround(height_px / 14.0)));
}
}  // namespace

float TextWidthPx(const std::string& text, float height_px) {
  int baseline = 0;
  return static_cast<float>(
      cv::getTextSize(text, kFont, FontScale(height_px), FontThickness(height_px), &baseline)
          .width);
}

void DrawTexts(const Scene& scene, RgbaImage* image) {
  cv::Mat canvas(image->height, image->width, CV_8UC4, image->pixels.data());
  for (const SceneText& t : scene.texts()) {
    const double scale = FontScale(t.height_px);
    const int thickness = FontThickness(t.height_px);
    int baseline = 0;
    const cv::Size size = cv::getTextSize(t.text, kFont, scale, thickness, &baseline);
    int x = static_cast<int>(std::lround(t.position.x));
    if (t.anchor == TextAnchor::kCenter) x -= size.width / 2;
    if (t.anchor == TextAnchor::kRight) x -= size.width;
    // Our buffer is RGBA, so the scalar is given in that order.
    cv::putText(canvas, t.text, {x, static_cast<int>(std::lround(t.position.y))}, kFont, scale,
                cv::Scalar(t.color.r, t.color.g, t.color.b, t.color.a), thickness, cv::LINE_AA);
  }
}

}  // namespace ratslam::render
