// Place recognition over image sequences after Milford and Wyeth, "SeqSLAM: Visual route-based
// navigation for sunny summer days and stormy winter nights" (ICRA 2012): images are patch
// normalised, every query is compared with every reference by mean absolute difference, each
// query's row of differences is contrast-enhanced over a window of references (the paper's
// eq. 1), and a query is placed by the best straight line through the last `sequence_length`
// rows over a range of velocities (references per query frame). The published parameter values
// (64x32 images, patch side 8, sequence length 10, velocities 0.8 to 1.2, a window of 10
// references) are the defaults.
//
// The matcher is incremental: a query costs one row of differences against the references
// (8-bit SIMD sums of absolute differences) and one search, never a rebuild. Frames with almost
// no contrast (black frames in tunnels, lens caps) are "blank": a blank query is declined and a
// blank reference is never the answer.
#ifndef RATSLAM_SENSORS_SEQUENCE_MATCHER_H_
#define RATSLAM_SENSORS_SEQUENCE_MATCHER_H_

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "common/schema.h"
#include "common/status.h"

namespace ratslam::sensors {

struct SequenceMatcherOptions {
  int patch_px = 8;             // side of the patches normalised to zero mean, unit spread
  int sequence_length = 10;     // query frames in a sequence (the paper's d_s)
  double min_velocity = 0.8;    // slowest line searched, reference frames per query frame
  double max_velocity = 1.2;    // fastest
  int velocity_steps = 5;       // velocities tried, evenly spaced from min to max
  int contrast_window = 10;     // references in the contrast-enhancement window (R_window)
  int exclusion_window = 10;    // references either side of the best kept out of the runner-up
  double blank_contrast = 8.0;  // grey levels, 5th to 95th percentile, under which: blank
  int image_width_px = 0;       // frames are resized to this width first (area average); 0: keep
  int image_height_px = 0;      // and to this height; 0: keep
  // Evaluate: a query's place from the sequence centred on it (OpenSeqSLAM's offline search)
  // instead of the one ending at it; online recognition (recognise_views) cannot use it.
  bool centred = false;
  // Replay (sequence recognition in the classic camera and fused front ends): a camera frame
  // whose sequence matches an earlier stretch of the route with at least min_confidence re-uses
  // the template of the frame it matched; a blank frame gives no view; otherwise the front end
  // decides as before.
  bool recognise_views = false;
  double min_confidence = 0.3;  // least margin of the best line over the runner-up, per frame
  int recency_frames = 50;      // the newest this-many frames are never matched
  int min_references = 100;     // frames older than recency_frames before anything is matched

  bool IsValid(std::string* error) const;

  template <typename Visitor>
  void VisitFields(Visitor&& v) {
    v("patch_px", patch_px, "side of the square patches normalised to zero mean and unit spread",
      schema::Unit("px").Within(1, 256));
    v("sequence_length", sequence_length,
      "query frames in a matched sequence (1: single frames, no sequence)",
      schema::Unit("frames").Within(1, 1000));
    v("min_velocity", min_velocity, "slowest line searched, reference frames per query frame",
      schema::Unit("frames/frame").Within(0, 100));
    v("max_velocity", max_velocity, "fastest line searched, reference frames per query frame",
      schema::Unit("frames/frame").Within(0, 100));
    v("velocity_steps", velocity_steps, "velocities tried, evenly spaced from min to max",
      schema::Unit("count").Within(1, 1000));
    v("contrast_window", contrast_window,
      "references in the window that enhances each difference's contrast (0: off)",
      schema::Unit("frames").Within(0, 100000));
    v("exclusion_window", exclusion_window,
      "references either side of the best match left out when finding the runner-up",
      schema::Unit("frames").Within(0, 100000));
    v("blank_contrast", blank_contrast,
      "grey levels between a frame's 5th and 95th percentiles below which it is blank (never "
      "matched)",
      schema::Unit("grey levels").Within(0, 255));
    v("image_width_px", image_width_px,
      "frames are first resized to this width by area averaging (0: as read); the paper used "
      "64x32",
      schema::Unit("px").Within(0, 4096));
    v("image_height_px", image_height_px, "and to this height (0: as read)",
      schema::Unit("px").Within(0, 4096));
    v("centred", centred,
      "evaluate: place a query by the best line through the sequence_length frames centred on "
      "it ((sequence_length - 1) / 2 of them after it; the last ones by the route's last "
      "frames), as OpenSeqSLAM's offline search does, instead of the frames ending at it; not "
      "with recognise_views (online)",
      schema::Any());
    v("recognise_views", recognise_views,
      "replay with the classic camera or fused (use_camera) front end: a camera frame whose "
      "sequence of the newest sequence_length frames matches an earlier stretch of the route "
      "with at least min_confidence re-uses the template of the frame it matched (a loop "
      "closure); a blank frame (blank_contrast) gives no view; otherwise the front end decides "
      "alone",
      schema::Any());
    v("min_confidence", min_confidence,
      "recognise_views: least margin of the best sequence over the best one outside "
      "exclusion_window, in contrast-enhanced differences per frame",
      schema::Unit("").Within(0, 1000));
    v("recency_frames", recency_frames,
      "recognise_views: frames this recent are never matched (the stretch just travelled)",
      schema::Unit("frames").Within(0, 1000000));
    v("min_references", min_references,
      "recognise_views: frames past recency_frames needed before a sequence is recognised (a "
      "margin over few candidates happens by chance)",
      schema::Unit("frames").Within(0, 1000000));
  }
};

// An image after patch normalisation: one byte per pixel (128 + 32 standard deviations of its
// patch, clamped), rows padded with 128 to a multiple of 32 bytes.
struct PreparedFrame {
  int width = 0, height = 0;
  std::vector<uint8_t> bytes;
  bool blank = false;
};

// `pixels` is width x height, rows top to bottom without padding.
PreparedFrame PrepareFrame(const uint8_t* pixels, int width, int height, int patch_px,
                           double blank_contrast);

// `pixels` (width x height, unpadded) resized to `to_width` x `to_height` by area averaging
// (each output pixel the mean of the input area it covers, partial pixels weighted by their
// share), rounded to the nearest grey level. Sizes must be positive.
std::vector<uint8_t> ResizeByArea(const uint8_t* pixels, int width, int height, int to_width,
                                  int to_height);

// PrepareFrame after the resize the options ask for (image_width_px / image_height_px).
PreparedFrame PrepareFrame(const uint8_t* pixels, int width, int height,
                           const SequenceMatcherOptions& options);

// Mean absolute difference per pixel (0..255) of two frames of one size.
double FrameDifference(const PreparedFrame& a, const PreparedFrame& b);

struct PlaceCandidate {
  int reference = -1;  // index of the reference
  double score = 0.0;  // lower is better (the sequence's summed enhanced difference)
};

// Up to `count` places, best first (lowest score; a tie goes to the lower index), none within
// `exclusion` references of a better one; places with an infinite or NaN score are never taken.
// A scan per place (count is small): sorting every reference cost more than a whole search.
std::vector<PlaceCandidate> PlaceCandidates(const std::vector<double>& score, int count,
                                            int exclusion);

struct SequenceMatch {
  bool declined = true;  // blank query, or no reference to match
  int reference = -1;    // the best reference (the place of the newest query frame)
  // How much better the best is than the best outside the exclusion window around it: a margin
  // in the units of the score per frame, larger is surer (0 when there is no runner-up).
  double confidence = 0.0;
  std::vector<PlaceCandidate> candidates;  // best first, each outside the others' windows
};

class SequenceMatcher {
 public:
  // `options` must be valid (IsValid); throws std::invalid_argument otherwise.
  explicit SequenceMatcher(const SequenceMatcherOptions& options);

  // References in route order; all frames (references and queries) must have one size. Queries
  // made before a reference was added treat it as unseen (a neutral term) in later searches, so
  // one route can be queried and then added, frame by frame (recognition while mapping).
  Status AddReference(PreparedFrame frame);
  size_t references() const { return references_.size(); }
  bool reference_blank(size_t i) const { return references_[i].blank; }

  // The next query frame of the route being localised: its place by the sequence ending at it
  // (`sequence`), and by itself alone (`single`: the smallest raw difference, the baseline).
  // Up to `candidates` places each.
  struct Result {
    SequenceMatch sequence;
    SequenceMatch single;
    std::vector<float> differences;  // this query's raw row (mean absolute difference 0..255)
  };
  // Only references below `searchable` (all when negative) can be answers.
  StatusOr<Result> AddQuery(const PreparedFrame& frame, int candidates = 5, int searchable = -1);
  // The same for a query known only by its row of differences to the references (one per
  // reference, in their order; lower is more alike, any non-negative finite scale, e.g. 1 - the
  // cosine similarity of place descriptors computed elsewhere). Such references need no pixels:
  // a PreparedFrame with only `blank` set stands for one. Fails on a row of the wrong length or
  // a negative or non-finite difference.
  StatusOr<Result> AddQueryDifferences(std::vector<float> differences, bool blank,
                                       int candidates = 5, int searchable = -1);

  // The place of the query `back` frames before the newest (0 <= back < queries_in_sequence())
  // by the best line through all the stored query frames, newer ones included: with back about
  // sequence_length / 2, the sequence centred on that query (OpenSeqSLAM's offline search),
  // which an online matcher cannot use. Declined for a blank query or an out-of-range `back`.
  // Every reference can be the answer.
  SequenceMatch MatchAt(int back, int candidates = 5) const;

  // Query frames in the current sequence (at most sequence_length).
  size_t queries_in_sequence() const { return rows_.size(); }
  // Forgets the queries (a new query route starts); the references stay.
  void ResetQueries() { rows_.clear(); }

  struct Row {
    std::vector<float> enhanced;  // contrast-enhanced differences, one per reference then known
    float neutral = 0.0f;         // at blank references, and for lines before the route starts
    bool blank = false;
  };
  // Everything a later query depends on, for saving and resuming.
  struct State {
    std::vector<PreparedFrame> references;
    std::deque<Row> rows;
  };
  State state() const { return {references_, rows_}; }
  // Fails, keeping the current state, on frames of different sizes or wrong byte counts, more
  // rows than sequence_length, a row longer than the references or holding NaN.
  Status SetState(State state);

 private:
  SequenceMatch Search(int back, int answers, int candidates) const;
  // Enhances and stores a query's row (of references_.size() differences) and searches.
  Result Match(std::vector<float> differences, bool blank, int candidates, int answers);

  SequenceMatcherOptions options_;
  std::vector<PreparedFrame> references_;  // in route order
  std::deque<Row> rows_;                   // the newest sequence_length query rows, newest last
};

}  // namespace ratslam::sensors

#endif  // RATSLAM_SENSORS_SEQUENCE_MATCHER_H_
