#include "core/log.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>

namespace ts::log {
namespace {

Level level_from_environment() {
  const char* env = std::getenv("TETRASAND_LOG");
  if (!env) return Level::Info;
  const std::string value(env);
  if (value == "error") return Level::Error;
  if (value == "warn") return Level::Warn;
  if (value == "debug") return Level::Debug;
  return Level::Info;
}

std::atomic<Level>& current() {
  static std::atomic<Level> value{level_from_environment()};
  return value;
}

}  // namespace

void set_level(Level value) { current() = value; }
Level level() { return current(); }

void write(Level message_level, std::string_view message) {
  static std::mutex mutex;
  static constexpr const char* prefix[] = {"error: ", "warning: ", "", "debug: "};
  std::lock_guard lock(mutex);
  std::fprintf(stderr, "%s%.*s\n", prefix[static_cast<int>(message_level)], static_cast<int>(message.size()),
               message.data());
}

}  // namespace ts::log
