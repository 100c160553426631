// A short fuzz pass without libFuzzer: the CI build is GCC's, and libFuzzer needs clang
// (scripts/fuzz.sh builds the real targets with clang, ASan and UBSan for the long runs). This driver
// links the same LLVMFuzzerTestOneInput as a target's libFuzzer build and feeds it, for a fixed time,
// inputs made from its seeds by random mutations (bytes flipped, inserted, erased, repeated, spliced;
// numbers in text replaced by the values that broke the readers before: 1e308, inf, nan, -0, 1e-320...;
// 8-byte doubles of the same values written into binary inputs). A run is reproducible from its seed.
//
//   TARGET_ci [--seconds S] [--seed N] [--crashes DIR] [--max-len BYTES] PATH...
//
// PATH: seed files, or folders of them (every regular file inside, sorted). Each seed is run once
// unmutated first, so the regression inputs kept in fuzz/regressions/TARGET/ are replayed every run.
// A crash (a signal, an exception escaping the target, a target's own check failing with abort) or an
// input slower than 10 s leaves the input as DIR/crash-N (or slow-N) and exits non-zero; the input is
// written from the signal handler, so even a stack overflow keeps it.
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <limits>
#include <stdexcept>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <string_view>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
// Defined by targets that keep counts of how their inputs ended (fuzz/run_checks.h); weak, so the
// others link without it.
extern "C" const char* TetrasandFuzzSummary() __attribute__((weak));

namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

// The input being run, where the signal handlers can write it out with async-signal-safe calls only.
const std::uint8_t* g_input = nullptr;
std::size_t g_input_size = 0;
char g_crash_path[4096] = {};
char g_slow_path[4096] = {};
constexpr unsigned kSlowSeconds = 10;

void write_input(const char* path) {
  const int fd = ::open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return;
  std::size_t done = 0;
  while (done < g_input_size) {
    const ssize_t n = ::write(fd, g_input + done, g_input_size - done);
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  ::close(fd);
}

void say(const char* a, const char* b) {
  (void)!::write(2, a, std::strlen(a));
  (void)!::write(2, b, std::strlen(b));
  (void)!::write(2, "\n", 1);
}

void on_crash(int signal_number) {
  write_input(g_crash_path);
  say("fuzz driver: crashed; the input is in ", g_crash_path);
  ::signal(signal_number, SIG_DFL);
  ::raise(signal_number);
}

void on_slow(int) {
  write_input(g_slow_path);
  say("fuzz driver: an input ran over 10 s; it is in ", g_slow_path);
  ::_exit(3);
}

void install_handlers() {
  // The stack-overflow case runs the handler on a stack of its own.
  static std::array<char, 1 << 16> alternate_stack;
  stack_t stack{};
  stack.ss_sp = alternate_stack.data();
  stack.ss_size = alternate_stack.size();
  ::sigaltstack(&stack, nullptr);
  struct sigaction action {};
  action.sa_handler = on_crash;
  action.sa_flags = SA_ONSTACK;
  for (int s : {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL}) ::sigaction(s, &action, nullptr);
  action.sa_handler = on_slow;
  ::sigaction(SIGALRM, &action, nullptr);
}

struct Options {
  double seconds = 20;
  std::uint64_t seed = 1;
  fs::path crashes = ".";
  std::size_t max_len = 1 << 16;
  std::vector<fs::path> paths;
};

[[noreturn]] void usage(const std::string& problem) {
  std::fprintf(stderr, "fuzz driver: %s\nusage: TARGET_ci [--seconds S] [--seed N] [--crashes DIR] "
               "[--max-len BYTES] PATH...\n", problem.c_str());
  std::exit(2);
}

Options parse_options(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(std::string(a) + " needs a value");
      return argv[++i];
    };
    try {
      if (a == "--seconds") o.seconds = std::stod(value());
      else if (a == "--seed") o.seed = std::stoull(value());
      else if (a == "--crashes") o.crashes = value();
      else if (a == "--max-len") o.max_len = std::stoull(value());
      else if (a.starts_with("--")) usage("unknown option " + std::string(a));
      else o.paths.emplace_back(a);
    } catch (const std::logic_error&) {
      usage("not a number after " + std::string(a));
    }
  }
  if (o.paths.empty()) usage("no seed files or folders given");
  return o;
}

Bytes read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<Bytes> read_seeds(const Options& o) {
  std::vector<fs::path> files;
  for (const fs::path& p : o.paths) {
    if (fs::is_directory(p)) {
      for (const auto& entry : fs::directory_iterator(p))
        if (entry.is_regular_file()) files.push_back(entry.path());
    } else if (fs::is_regular_file(p)) {
      files.push_back(p);
    } else {
      usage("no such seed file or folder: " + p.string());
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<Bytes> seeds;
  for (const fs::path& f : files) seeds.push_back(read_bytes(f));
  if (seeds.empty()) seeds.emplace_back();  // an empty input is a seed too
  return seeds;
}

// The values that broke readers before (docs/reliability.md, issue 46): overflowing, non-finite,
// denormal, signed zero, beyond 32 and 64 bits.
constexpr std::array<std::string_view, 14> kTextNumbers = {
    "1e308", "-1e308", "inf", "-inf", "nan", "-0.0", "0", "1e-320", "1e200", "4294967296",
    "9223372036854775808", "-1", "1e38", "99999999999999999999"};
constexpr std::array<double, 9> kBinaryNumbers = {1e308, -1e308, 1e200, 0.0, -0.0, 4.9e-324, 1e38, -1.0, 0.5};

class Mutator {
 public:
  explicit Mutator(std::uint64_t seed, std::size_t max_len) : rng_(seed), max_len_(max_len) {}

  Bytes mutate(const std::vector<Bytes>& seeds) {
    Bytes b = seeds[below(seeds.size())];
    const std::size_t edits = 1 + below(4);
    for (std::size_t e = 0; e < edits; ++e) edit(b, seeds);
    if (b.size() > max_len_) b.resize(max_len_);
    return b;
  }

 private:
  std::size_t below(std::size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }

  void edit(Bytes& b, const std::vector<Bytes>& seeds) {
    switch (below(8)) {
      case 0: if (!b.empty()) b[below(b.size())] ^= static_cast<std::uint8_t>(1u << below(8)); break;
      case 1: b.insert(b.begin() + static_cast<long>(below(b.size() + 1)), static_cast<std::uint8_t>(below(256))); break;
      case 2: erase_range(b); break;
      case 3: repeat_range(b); break;
      case 4: splice(b, seeds[below(seeds.size())]); break;
      case 5: case 6: replace_text_number(b); break;
      default: write_binary_number(b); break;
    }
  }
  void erase_range(Bytes& b) {
    if (b.empty()) return;
    const std::size_t at = below(b.size()), n = 1 + below(std::min<std::size_t>(16, b.size() - at));
    b.erase(b.begin() + static_cast<long>(at), b.begin() + static_cast<long>(at + n));
  }
  void repeat_range(Bytes& b) {
    if (b.empty()) return;
    const std::size_t at = below(b.size()), n = 1 + below(std::min<std::size_t>(64, b.size() - at));
    const Bytes piece(b.begin() + static_cast<long>(at), b.begin() + static_cast<long>(at + n));
    const std::size_t times = 1 + below(8);
    for (std::size_t t = 0; t < times && b.size() < max_len_; ++t)
      b.insert(b.begin() + static_cast<long>(at), piece.begin(), piece.end());
  }
  void splice(Bytes& b, const Bytes& other) {
    if (other.empty()) return;
    const std::size_t from = below(other.size()), n = 1 + below(std::min<std::size_t>(256, other.size() - from));
    b.insert(b.begin() + static_cast<long>(below(b.size() + 1)), other.begin() + static_cast<long>(from),
             other.begin() + static_cast<long>(from + n));
  }
  // A run of digits (with its sign, point and exponent) replaced by one of kTextNumbers.
  void replace_text_number(Bytes& b) {
    std::vector<std::size_t> starts;
    for (std::size_t i = 0; i < b.size(); ++i)
      if (std::isdigit(b[i]) && (i == 0 || !std::isdigit(b[i - 1]) && b[i - 1] != '.')) starts.push_back(i);
    if (starts.empty()) return write_binary_number(b);
    std::size_t at = starts[below(starts.size())], end = at;
    if (at > 0 && b[at - 1] == '-') --at;
    while (end < b.size() && (std::isdigit(b[end]) || b[end] == '.' || b[end] == 'e' || b[end] == 'E' ||
                              ((b[end] == '-' || b[end] == '+') && (b[end - 1] == 'e' || b[end - 1] == 'E'))))
      ++end;
    const std::string_view v = kTextNumbers[below(kTextNumbers.size())];
    b.erase(b.begin() + static_cast<long>(at), b.begin() + static_cast<long>(end));
    b.insert(b.begin() + static_cast<long>(at), v.begin(), v.end());
  }
  void write_binary_number(Bytes& b) {
    double v = kBinaryNumbers[below(kBinaryNumbers.size())];
    if (below(4) == 0) v = below(2) ? std::numeric_limits<double>::infinity() : std::numeric_limits<double>::quiet_NaN();
    std::uint8_t bytes[8];
    std::memcpy(bytes, &v, 8);
    if (b.size() < 8) {
      b.insert(b.end(), bytes, bytes + 8);
      return;
    }
    std::memcpy(&b[below(b.size() - 7)], bytes, 8);
  }

  std::mt19937_64 rng_;
  std::size_t max_len_;
};

// Runs one input with the crash bookkeeping around it; false when an exception escaped the target.
bool run_one(const Bytes& input) {
  g_input = input.data();
  g_input_size = input.size();
  ::alarm(kSlowSeconds);
  try {
    LLVMFuzzerTestOneInput(input.data(), input.size());
  } catch (const std::exception& e) {
    ::alarm(0);
    write_input(g_crash_path);
    std::fprintf(stderr, "fuzz driver: an exception escaped the target: %s; the input is in %s\n", e.what(),
                 g_crash_path);
    return false;
  }
  ::alarm(0);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse_options(argc, argv);
  fs::create_directories(o.crashes);
  const std::string stem = (o.crashes / fs::path(argv[0]).filename()).string();
  std::snprintf(g_crash_path, sizeof g_crash_path, "%s-crash-seed%llu", stem.c_str(),
                static_cast<unsigned long long>(o.seed));
  std::snprintf(g_slow_path, sizeof g_slow_path, "%s-slow-seed%llu", stem.c_str(),
                static_cast<unsigned long long>(o.seed));
  install_handlers();
  const std::vector<Bytes> seeds = read_seeds(o);
  for (const Bytes& s : seeds)
    if (!run_one(s)) return 1;
  Mutator mutator(o.seed, o.max_len);
  const auto start = std::chrono::steady_clock::now();
  std::size_t runs = seeds.size();
  while (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < o.seconds) {
    if (!run_one(mutator.mutate(seeds))) return 1;
    ++runs;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s: %zu inputs (%zu seeds unmutated), %.1f s, seed %llu: no crash, no failed check\n",
              fs::path(argv[0]).filename().c_str(), runs, seeds.size(), seconds,
              static_cast<unsigned long long>(o.seed));
  if (TetrasandFuzzSummary != nullptr) std::printf("  %s\n", TetrasandFuzzSummary());
  return 0;
}
