#pragma once
// The World's arrays as bytes, and back: the engine's share of a checkpoint (scene/checkpoint.h) and of
// a scene's hash. world_from_bytes throws what ByteReader::fail throws (sim/state_bytes.h) on bytes
// that are short, left over or describe a world that does not hang together.
#include <string>

#include "sim/state_bytes.h"
#include "sim/world.h"

namespace ts::sim {

std::string world_bytes(const World& world);
World world_from_bytes(ByteReader& reader);

}  // namespace ts::sim
