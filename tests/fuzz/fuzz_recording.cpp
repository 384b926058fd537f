// libFuzzer target: any bytes as a recording. parse_mcap (strict and allow_truncated) and
// decode_recording must return a value or an error naming a byte offset; never crash, hang,
// read out of bounds or allocate without bound (tests/fuzz/run.sh runs it under ASan + UBSan).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/recording/mcap.hpp"
#include "core/recording/recording.hpp"

namespace {

// A violated promise is a finding: abort, and libFuzzer keeps the input.
void require(bool ok) {
  if (!ok) std::abort();
}

void check(const std::vector<uint8_t>& bytes, bool allow_truncated) {
  mixpilot::McapReadOptions options;
  options.allow_truncated = allow_truncated;
  std::string error;
  const auto file = mixpilot::parse_mcap(bytes, "fuzz.mcap", error, options);
  if (!file) {
    require(error.rfind("fuzz.mcap: ", 0) == 0 && error.find(" at byte ") != std::string::npos);
    return;
  }
  require(file->parsed_bytes <= bytes.size());
  require(!file->complete || file->parsed_bytes == bytes.size());
  for (const auto& m : file->messages) require(m.data_offset + m.data_size <= bytes.size());
  const auto contents = mixpilot::decode_recording(*file, "fuzz.mcap", error);
  if (!contents)
    require(error.rfind("fuzz.mcap: ", 0) == 0 && error.find(" at byte ") != std::string::npos);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::vector<uint8_t> bytes(data, data + size);
  check(bytes, false);
  check(bytes, true);
  return 0;
}
