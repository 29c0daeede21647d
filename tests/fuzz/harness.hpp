#pragma once
// The fuzz targets: one per reader or parser of user files. A target owns a small valid instance
// of its input (written by prepare(), with whatever companion files the reader needs), and each
// execution replaces the fuzzed file with the fuzzer's bytes and runs the reader as gvio does.
//
// The same targets run three ways: as libFuzzer executables (tests/fuzz/fuzz_main.cpp, built by
// ./setup.sh fuzz), in the normal test suite over the committed corpus and every input a fuzzer
// once broke (tests/unit/fuzz_corpus_test.cpp), and in tests/fuzz/make_seeds.cpp, which writes the
// seed corpus from prepare().
#include <cstddef>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace gvio::fuzz {

// A reader returned something it must never return (a NaN pose, an unordered stream, ...).
class InvariantViolation : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

// Throws InvariantViolation with `what` when `ok` is false.
void require(bool ok, const std::string& what);

struct Target {
  std::string name;
  std::string file;  // the fuzzed file, relative to the target's folder
  // Writes a valid instance of `file` and its companions into the target's folder.
  std::function<void(const std::filesystem::path& dir)> prepare;
  // Reads the fuzzed input the way gvio does and checks what it got (InvariantViolation).
  std::function<void(const std::filesystem::path& dir)> read;
  // What a refusal must name; empty: the file's name. "-" for targets whose input is no file of
  // its own (a message inside a container names the container one level up).
  std::string names;
};

// Every target, in a fixed order.
const std::vector<Target>& targets();
const Target* findTarget(std::string_view name);

enum class Verdict {
  kAccepted,  // read without complaint
  kRejected,  // refused with one line that names the file (InvalidInput): what bad input must get
  kBug,       // anything else: another exception, a message that does not name the file, or a
              // broken invariant (a crash, hang or sanitizer report ends the process instead)
};

struct Outcome {
  Verdict verdict = Verdict::kAccepted;
  std::string message;
};

// A target's folder under the system temp dir, prepared once per process and removed at exit.
std::filesystem::path workspace(const Target& target);

// Writes `input` as the target's file and reads it.
Outcome runInput(const Target& target, std::string_view input);

// The prepared (valid) content of the target's file: its seed.
std::string seedOf(const Target& target);

std::string toString(Verdict verdict);

}  // namespace gvio::fuzz
