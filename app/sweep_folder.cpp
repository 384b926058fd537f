#include "app/sweep_folder.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>
#include <system_error>
#include <thread>

#include "app/cli.hpp"
#include "core/base/input_file.hpp"
#include "core/base/output_file.hpp"
#include "core/scenario/scenario_toml.hpp"

namespace mixpilot::cli {

namespace {

namespace fs = std::filesystem;

// Whether `name` is a temporary of "<base>" (core/base/output_file.hpp: "<base>.XXXXXX.tmp").
bool temporary_of(const std::string& name, const std::string& base) {
  constexpr std::size_t kSuffix = 11;  // ".XXXXXX.tmp"
  if (name.size() != base.size() + kSuffix || name.compare(0, base.size(), base) != 0) return false;
  if (name[base.size()] != '.' || !name.ends_with(".tmp")) return false;
  for (std::size_t i = base.size() + 1; i < base.size() + 7; ++i)
    if (!std::isalnum(static_cast<unsigned char>(name[i]))) return false;
  return true;
}

// The short form of a hash for messages.
std::string short_hash(const std::string& h) { return h.substr(0, 12); }

}  // namespace

std::string duration_text(double s) {
  char buf[64];
  if (!(s >= 0.0) || !std::isfinite(s)) return "?";
  if (s < 60.0) {
    std::snprintf(buf, sizeof buf, "%.1f s", s);
  } else if (s < 3600.0) {
    std::snprintf(buf, sizeof buf, "%d min %d s", int(s / 60.0), int(std::fmod(s, 60.0)));
  } else {
    std::snprintf(buf, sizeof buf, "%d h %d min", int(s / 3600.0), int(std::fmod(s, 3600.0) / 60.0));
  }
  return buf;
}

std::string id_list(const std::vector<std::string>& ids, std::size_t show) {
  std::string out;
  for (std::size_t i = 0; i < ids.size() && i < show; ++i) out += (i ? ", " : "") + ids[i];
  if (ids.size() > show) out += " and " + std::to_string(ids.size() - show) + " more";
  return out;
}

std::vector<std::size_t> shard_runs(std::size_t total, const std::optional<Shard>& shard) {
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < total; ++k)
    if (!shard || in_shard(k, *shard)) out.push_back(k);
  return out;
}

bool ResultFolder::check_plan(const std::string& text, std::string& error) const {
  std::string why;
  const std::optional<JsonValue> j = parse_json(text, why);
  const std::string* hash = j ? j->string_at("plan_sha256") : nullptr;
  const std::string* format = j ? j->string_at("format") : nullptr;
  if (!hash || !format || !format->starts_with(plan_.format)) {
    error = dir_ + "/plan.json is not the plan of a " + plan_.format + " folder" +
            (j ? "" : " (" + why + ")") + ": give another --out, or remove " + dir_ +
            " to start over";
    return false;
  }
  if (*hash == plan_.sha256) return true;
  // What differs, as far as the ids say.
  std::vector<std::string> theirs;
  if (const JsonValue* runs = j->get("runs"); runs && runs->is(JsonValue::Type::array))
    for (const JsonValue& r : runs->items)
      if (const std::string* id = r.string_at("id")) theirs.push_back(*id);
  std::string detail;
  if (theirs.size() != plan_.ids.size()) {
    detail = "it has " + std::to_string(theirs.size()) + " runs, this plan " +
             std::to_string(plan_.ids.size());
  } else {
    for (std::size_t i = 0; i < theirs.size(); ++i)
      if (theirs[i] != plan_.ids[i]) {
        detail = "its run " + std::to_string(i) + " is " + theirs[i] + ", this plan's " + plan_.ids[i];
        break;
      }
    if (detail.empty()) detail = "the same runs, flying other scenarios or options";
  }
  error = dir_ + " holds the results of another plan (plan_sha256 " + short_hash(*hash) +
          "…, this one's " + short_hash(plan_.sha256) + "…; " + detail +
          "): the sweep file, its scenario or the recordings changed since. Results of two plans "
          "are never mixed: give another --out, or remove " + dir_ + " to start over";
  return false;
}

bool ResultFolder::claim(const std::string& dir, const FolderPlan& plan, std::string& error) {
  dir_ = dir;
  plan_ = plan;
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (fs::exists(st) && !fs::is_directory(st)) {
    error = dir + " exists and is not a folder: give another --out";
    return false;
  }
  const std::string plan_path = dir + "/plan.json";
  if (!fs::exists(st)) {
    fs::create_directories(dir, ec);
    if (ec) {
      error = dir + ": cannot create the folder: " + ec.message();
      return false;
    }
  }
  std::string text;
  if (fs::exists(plan_path, ec)) {
    if (!read_text_file(plan_path, text, error)) return false;
    if (!check_plan(text, error)) return false;
  } else {
    // Not someone else's folder: empty, or what another process claiming it at the same
    // moment has written so far.
    for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
      const std::string name = e.path().filename().string();
      if (name == "runs" || name == "plan.json" || temporary_of(name, "plan.json")) continue;
      error = dir + " is not empty and holds no plan.json: it is not a folder of " + plan.format +
              "; give another --out (or an empty folder)";
      return false;
    }
    if (ec) {
      error = dir + ": cannot list the folder: " + ec.message();
      return false;
    }
    std::string why;
    if (!write_file(plan_path, plan.json, /*overwrite=*/false, why)) {
      // Another process claiming the folder wrote it first: then it must be this plan.
      if (!fs::exists(plan_path, ec)) {
        error = why;
        return false;
      }
      if (!read_text_file(plan_path, text, error) || !check_plan(text, error)) return false;
    }
  }
  fs::create_directories(dir + "/runs", ec);
  if (ec) {
    error = dir + "/runs: cannot create the folder: " + ec.message();
    return false;
  }
  return true;
}

bool ResultFolder::open_existing(const std::string& dir, const FolderPlan& plan,
                                 std::string& error) {
  dir_ = dir;
  plan_ = plan;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    error = dir + ": no such folder: nothing has been flown into it (run without --merge first)";
    return false;
  }
  std::string text;
  if (!fs::exists(dir + "/plan.json", ec)) {
    error = dir + " holds no plan.json: it is not a folder of " + plan.format;
    return false;
  }
  return read_text_file(dir + "/plan.json", text, error) && check_plan(text, error);
}

std::string ResultFolder::run_path(const std::string& id) const {
  return dir_ + "/runs/" + id + ".json";
}

bool ResultFolder::finished(const std::string& id) const {
  std::error_code ec;
  const std::string path = run_path(id);
  if (!fs::exists(path, ec)) return false;
  std::string text, error;
  if (!read_text_file(path, text, error)) return false;
  const std::optional<JsonValue> j = parse_json(text, error);
  if (!j) return false;
  const std::string* format = j->string_at("format");
  const std::string* hash = j->string_at("plan_sha256");
  const std::string* its_id = j->string_at("id");
  return format && format->starts_with(plan_.format) && hash && *hash == plan_.sha256 && its_id &&
         *its_id == id && j->get("report");
}

void ResultFolder::clear_leftovers(const std::vector<std::string>& ids, const std::string& folder,
                                   const std::string& ext) const {
  const std::set<std::string> mine(ids.begin(), ids.end());
  std::error_code ec;
  std::vector<fs::path> stale;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
    const std::string name = e.path().filename().string();
    if (name.size() <= 11 + ext.size()) continue;
    const std::string base = name.substr(0, name.size() - 11);  // "<id><ext>"
    if (!base.ends_with(ext) || !temporary_of(name, base)) continue;
    if (mine.count(base.substr(0, base.size() - ext.size()))) stale.push_back(e.path());
  }
  for (const fs::path& p : stale) fs::remove(p, ec);
}

bool ResultFolder::write_run(const std::string& id, const std::string& json,
                             std::string& error) const {
  // Over a file only when it is no finished run of this plan or with --force: finished() read
  // it to know, which makes it one of this process's inputs, here rewritten on purpose.
  OutputFile out;
  if (!out.open(run_path(id), /*overwrite=*/true, error, InputReplacement::allowed)) return false;
  if (std::fwrite(json.data(), 1, json.size(), out.stream()) != json.size()) {
    error = run_path(id) + ": write failed: " + std::strerror(errno) + "; nothing written";
    out.discard();
    return false;
  }
  return out.commit(error, /*keep_partial=*/false);
}

ResultFolder::Gathered ResultFolder::gather() const {
  Gathered g;
  for (const std::string& id : plan_.ids) {
    const std::string path = run_path(id);
    std::error_code ec;
    if (!fs::exists(path, ec)) {
      g.missing.push_back(id);
      continue;
    }
    std::string text, error;
    if (!read_text_file(path, text, error)) {
      g.bad.push_back(error);
      continue;
    }
    std::optional<JsonValue> j = parse_json(text, error);
    if (!j) {
      g.bad.push_back(path + ": not a run's JSON (" + error + ")");
      continue;
    }
    const std::string* format = j->string_at("format");
    const std::string* hash = j->string_at("plan_sha256");
    const std::string* its_id = j->string_at("id");
    const JsonValue* report = j->get("report");
    if (!format || !format->starts_with(plan_.format) || !its_id || *its_id != id || !report ||
        !report->is(JsonValue::Type::object)) {
      g.bad.push_back(path + ": not the run " + id + " of a " + plan_.format + " folder");
      continue;
    }
    if (!hash || *hash != plan_.sha256) {
      g.bad.push_back(path + ": a run of another plan (plan_sha256 " +
                      (hash ? short_hash(*hash) + "…" : std::string("missing")) +
                      "); remove it, or fly it again with --force");
      continue;
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    g.runs.push_back(std::move(*j));
    g.texts.push_back(std::move(text));
  }
  return g;
}

bool ResultFolder::write_tables(const Gathered& g, const std::string& csv,
                                std::string& error) const {
  std::string json = "[\n";
  for (std::size_t i = 0; i < g.texts.size(); ++i) json += g.texts[i] + (i + 1 < g.texts.size() ? ",\n" : "\n");
  json += "]\n";
  // The folder's own derived files: each merge writes them anew.
  return write_file(dir_ + "/table.csv", csv, /*overwrite=*/true, error) &&
         write_file(dir_ + "/table.json", json, /*overwrite=*/true, error);
}

PoolResult run_pool(const char* command, const ResultFolder& folder,
                    const std::vector<std::string>& ids, const std::vector<std::size_t>& todo,
                    std::size_t done_before, std::size_t total, int jobs,
                    const std::function<RunOutcome(std::size_t)>& fly) {
  PoolResult result;
  std::atomic<std::size_t> next{0};
  std::size_t completed = 0, finished = done_before;
  std::mutex io;
  const auto t0 = std::chrono::steady_clock::now();
  const auto worker = [&] {
    for (std::size_t n = next++; n < todo.size() && !interrupted(); n = next++) {
      const std::size_t k = todo[n];
      const auto started = std::chrono::steady_clock::now();
      RunOutcome out = fly(k);
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      std::string error = out.error;
      if (out.ok && !folder.write_run(ids[k], out.json, error)) out.ok = false;
      const std::lock_guard<std::mutex> lock(io);
      if (out.interrupted) {
        result.interrupted = true;
        continue;
      }
      ++completed;
      ++result.flown;
      if (out.ok) ++finished;
      else ++result.failed;
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const std::size_t left = todo.size() - completed;
      const std::string eta =
          left > 0 ? "; ETA " + duration_text(elapsed / double(completed) * double(left)) : "";
      if (out.ok) {
        std::fprintf(stderr, "mixpilot %s: [%zu/%zu] %s: %s (%s)%s\n", command, finished, total,
                     ids[k].c_str(), out.said.c_str(), duration_text(wall).c_str(), eta.c_str());
      } else {
        std::fprintf(stderr, "mixpilot %s: [%zu/%zu] %s FAILED: %s%s\n", command, finished, total,
                     ids[k].c_str(), error.c_str(), eta.c_str());
      }
      std::fflush(stderr);
    }
  };
  std::vector<std::thread> pool;
  const int n = std::max(1, std::min<int>(jobs, int(todo.size())));
  for (int j = 0; j < n; ++j) pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  if (interrupted()) result.interrupted = true;
  return result;
}

}  // namespace mixpilot::cli
