#include "sdf/openvdb_init.h"

#include <openvdb/openvdb.h>

#include <mutex>

namespace ts::sdf {

void ensure_openvdb_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

}  // namespace ts::sdf
