// Wi-Fi received power: a log-distance path-loss model with the free-space loss up to the
// reference distance, plus wall attenuation along the straight path (the multi-wall model of
// Motley and Keenan / COST 231) and a loss per floor between AP and receiver:
//   P = P_tx - FSPL(d0, f) - 10 n log10(d / d0) - sum(walls crossed) - floors * L_floor
//       + S(x, y) + F,
// FSPL(d, f) = 20 log10(d / 1 m) + 20 log10(f / 1 MHz) - 27.55 dB (Friis). S is log-normal
// shadowing that is the same at the same place: a Gaussian field per AP and floor, drawn on a
// grid of `shadowing_correlation_m` from the seed and interpolated bilinearly. F is independent
// per scan. Readings below the sensitivity are not reported; others go missing at random.
#ifndef RATSLAM_SIM_PROPAGATION_H_
#define RATSLAM_SIM_PROPAGATION_H_

#include <cstdint>
#include <vector>

#include "common/random.h"
#include "common/sensor_samples.h"
#include "sim/world.h"

namespace ratslam::sim {

// Centre frequency of a Wi-Fi channel (2.4 GHz: 2407 + 5 ch; 5 GHz: 5000 + 5 ch), MHz.
double ChannelFrequencyMhz(int channel);
// Free-space path loss (Friis), dB.
double FreeSpaceLossDb(double distance_m, double frequency_mhz);

class WifiPropagation {
 public:
  WifiPropagation(const World& world, uint64_t seed) : world_(world), seed_(seed) {}

  // Sum of the attenuations of the walls of `floor` that the segment a-b crosses.
  double WallLossDb(Point2 a, Point2 b, int floor) const;
  // Deterministic mean received power of access point `ap` (index) at a place, without
  // shadowing and fading, in `session` (moved APs).
  double MeanPowerDbm(size_t ap, Point2 at, int floor, int session) const;
  // The shadowing term S at a place (same place, same value).
  double ShadowingDb(size_t ap, Point2 at, int floor) const;
  // One scan: every AP on in `session`, heard above the sensitivity, and not missed.
  std::vector<WifiReading> Scan(Point2 at, int floor, int session, Random* random) const;

 private:
  const World& world_;
  uint64_t seed_;
};

}  // namespace ratslam::sim

#endif  // RATSLAM_SIM_PROPAGATION_H_
