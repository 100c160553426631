#include "sim/state_bytes.h"

#include <fmt/format.h>

#include "core/error.h"

namespace ts::sim {

void ByteReader::fail(const std::string& problem) const {
  throw InputError(fmt::format("{}: {} (at byte {} of {})", what_, problem, offset_, bytes_.size()));
}

}  // namespace ts::sim
