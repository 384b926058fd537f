#pragma once
// Files of the tests: fresh paths in a folder of the test process, the unique temporaries an output
// leaves beside its target ("<target>.XXXXXX.tmp", core/base/output_file.hpp), contents.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include <unistd.h>

namespace mixpilot::test {

namespace fs = std::filesystem;

// The temporaries beside `p`.
inline std::vector<fs::path> temporaries_of(const fs::path& p) {
  std::vector<fs::path> out;
  const std::string name = p.filename().string();
  for (const auto& e : fs::directory_iterator(p.parent_path())) {
    const std::string f = e.path().filename().string();
    if (f.size() == name.size() + 11 && f.rfind(name + ".", 0) == 0 && f.ends_with(".tmp"))
      out.push_back(e.path());
  }
  return out;
}

// This process's folder in the system's temporary directory, removed when the process exits:
// CTest runs tests in parallel processes, which must never share a file.
inline const fs::path& process_temp_dir() {
  struct Dir {
    fs::path path = fs::temp_directory_path() / ("mixpilot_test." + std::to_string(::getpid()));
    Dir() { fs::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      fs::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

// `name` in the folder `folder` of this process's temporary folder, with whatever an earlier
// test left there under that name (the file and its temporaries) removed.
inline fs::path fresh_path(const std::string& folder, const std::string& name) {
  const fs::path dir = process_temp_dir() / folder;
  fs::create_directories(dir);
  fs::remove_all(dir / name);
  for (const auto& t : temporaries_of(dir / name)) fs::remove(t);
  return dir / name;
}

inline std::vector<uint8_t> slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace mixpilot::test
