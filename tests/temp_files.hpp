#pragma once
// Files of the recording tests: fresh paths in a test folder, the unique temporaries an output
// leaves beside its target ("<target>.XXXXXX.tmp", core/recording/output_file.hpp), contents.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

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

// `name` in the folder `folder` of the system's temporary directory, with whatever an earlier
// run left there under that name (the file and its temporaries) removed.
inline fs::path fresh_path(const std::string& folder, const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / folder;
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
