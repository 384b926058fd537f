#pragma once
// The shard rule of sweeps and folder scoring (docs/sweeps.md): shard i of n (1-based) holds
// the runs whose 0-based plan index k has k mod n = i − 1. The n shards partition any plan,
// a run's shard depends on its index alone, and each shard is as long as any other to within
// one run, so a Slurm array of n tasks (or n machines) shares a plan evenly.
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <system_error>

namespace mixpilot {

inline constexpr std::int64_t kMaxShards = 1000000;

struct Shard {
  std::int64_t index = 1;  // i, 1-based
  std::int64_t count = 1;  // n
};

inline bool in_shard(std::size_t k, const Shard& s) {
  return std::int64_t(k % std::size_t(s.count)) == s.index - 1;
}

// "i/n" with whole numbers 1 <= i <= n <= kMaxShards; nullopt otherwise.
inline std::optional<Shard> parse_shard(std::string_view text) {
  const std::size_t slash = text.find('/');
  if (slash == std::string_view::npos) return std::nullopt;
  const auto whole = [](std::string_view t, std::int64_t& v) {
    if (t.empty() || t.size() > 9) return false;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    return r.ec == std::errc() && r.ptr == t.data() + t.size();
  };
  Shard s;
  if (!whole(text.substr(0, slash), s.index) || !whole(text.substr(slash + 1), s.count))
    return std::nullopt;
  if (s.index < 1 || s.count < 1 || s.index > s.count || s.count > kMaxShards) return std::nullopt;
  return s;
}

}  // namespace mixpilot
