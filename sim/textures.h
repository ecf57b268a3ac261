// Procedural grey textures for simulated walls, floors and people. A texture name is a kind
// with an optional variant, "posters:3": the same name always gives the same pixels, so views
// repeat where the world repeats (two floors with the same names look the same).
#ifndef RATSLAM_SIM_TEXTURES_H_
#define RATSLAM_SIM_TEXTURES_H_

#include <cstdint>
#include <string>
#include <vector>

namespace ratslam::sim {

// Kinds: plaster, brick, stripes, checker, tiles, wood, posters, door, noise, person, floor,
// ceiling.
bool IsTextureName(const std::string& name);
// A size x size grey texture (rows top down).
std::vector<uint8_t> MakeTexture(const std::string& name, int size);

}  // namespace ratslam::sim

#endif  // RATSLAM_SIM_TEXTURES_H_
