#pragma once
// Errors about an input named by it, whoever reports them: the commands (app/) and the Python module.
#include <filesystem>
#include <string>

#include "core/error.h"

namespace ts {

// Runs `step`, work on the input `file`: an InputError whose message does not start with the file's
// name gets it in front, so an error about a mesh's sizes (a voxel, a radius) says which mesh.
template <typename Step>
auto naming_file(const std::string& file, Step&& step) -> decltype(step()) {
  try {
    return step();
  } catch (const InputError& e) {
    const std::string message = e.what();
    if (message.rfind(file + ": ", 0) == 0) throw;
    throw InputError(std::filesystem::path(file), message);
  }
}

}  // namespace ts
