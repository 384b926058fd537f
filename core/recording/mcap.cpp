#include "core/recording/mcap.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>
#include <utility>

#include "core/base/input_file.hpp"
#include "core/numerics/version.hpp"

namespace mixpilot {

static_assert(std::endian::native == std::endian::little,
              "MCAP and CDR writers here assume a little-endian host");

// ---- CRC-32 -----------------------------------------------------------------------------

namespace {
// Slicing by 8 (Intel's method): table k maps a byte to its CRC contribution k bytes before the
// end of an 8-byte block, so a block takes eight independent lookups instead of a chain of eight
// dependent ones. Table 0 is the bytewise table.
using CrcTables = std::array<std::array<uint32_t, 256>, 8>;
constexpr CrcTables make_crc_tables() {
  CrcTables t{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (0xEDB88320u ^ (c >> 1)) : (c >> 1);
    t[0][i] = c;
  }
  for (std::size_t k = 1; k < t.size(); ++k)
    for (uint32_t i = 0; i < 256; ++i) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFFu];
  return t;
}
constexpr CrcTables kCrc = make_crc_tables();
}  // namespace

uint32_t crc32_update(uint32_t crc, const uint8_t* data, std::size_t size) {
  // The running value is kept finalized (post-XOR) so that 0 is the CRC of nothing and
  // updates chain without separate init/final calls.
  uint32_t c = crc ^ 0xFFFFFFFFu;
  for (; size >= 8; data += 8, size -= 8) {
    uint32_t lo, hi;  // little-endian host (static_assert above)
    std::memcpy(&lo, data, 4);
    std::memcpy(&hi, data + 4, 4);
    lo ^= c;
    c = kCrc[7][lo & 0xFFu] ^ kCrc[6][(lo >> 8) & 0xFFu] ^ kCrc[5][(lo >> 16) & 0xFFu] ^
        kCrc[4][lo >> 24] ^ kCrc[3][hi & 0xFFu] ^ kCrc[2][(hi >> 8) & 0xFFu] ^
        kCrc[1][(hi >> 16) & 0xFFu] ^ kCrc[0][hi >> 24];
  }
  for (; size > 0; ++data, --size) c = kCrc[0][(c ^ *data) & 0xFFu] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

// ---- writer -----------------------------------------------------------------------------

namespace {
void put_u8(std::vector<uint8_t>& b, uint8_t v) { b.push_back(v); }
template <class T>
void put_le(std::vector<uint8_t>& b, T v) {
  uint8_t tmp[sizeof(T)];
  std::memcpy(tmp, &v, sizeof(T));  // little-endian host (static_assert above)
  b.insert(b.end(), tmp, tmp + sizeof(T));
}
void put_bytes(std::vector<uint8_t>& b, std::string_view s) { b.insert(b.end(), s.begin(), s.end()); }
// Spec "Serialization/String": uint32 byte length + UTF-8 bytes.
void put_string(std::vector<uint8_t>& b, std::string_view s) {
  put_le<uint32_t>(b, static_cast<uint32_t>(s.size()));
  put_bytes(b, s);
}
// Spec "Serialization/Map": uint32 byte length of all entries, then key/value pairs.
void put_string_map(std::vector<uint8_t>& b, const McapStringMap& m) {
  const std::size_t at = b.size();
  put_le<uint32_t>(b, 0);
  for (const auto& [k, v] : m) {
    put_string(b, k);
    put_string(b, v);
  }
  const auto len = static_cast<uint32_t>(b.size() - at - 4);
  std::memcpy(b.data() + at, &len, 4);
}
bool fits_u32(std::size_t n) { return n <= std::numeric_limits<uint32_t>::max(); }
bool map_fits(const McapStringMap& m) {
  std::size_t total = 0;
  for (const auto& [k, v] : m) total += 8 + k.size() + v.size();
  return fits_u32(total);
}
}  // namespace

bool McapWriter::fail(std::string message) {
  if (error_.empty()) error_ = std::move(message);
  return false;
}

void McapWriter::begin(mcap::Opcode op) {
  record_.clear();
  put_u8(record_, static_cast<uint8_t>(op));
  put_le<uint64_t>(record_, 0);  // content length, patched in emit()
}

bool McapWriter::write_raw(const uint8_t* data, std::size_t size, bool in_data_section) {
  if (std::fwrite(data, 1, size, file_) != size)
    return fail(tmp_path() + ": write failed: " + std::strerror(errno));
  if (in_data_section) data_crc_ = crc32_update(data_crc_, data, size);
  if (summary_) summary_crc_ = crc32_update(summary_crc_, data, size);
  offset_ += size;
  return true;
}

bool McapWriter::emit(bool in_data_section) {
  const uint64_t len = record_.size() - 9;
  std::memcpy(record_.data() + 1, &len, 8);
  return write_raw(record_.data(), record_.size(), in_data_section);
}

bool McapWriter::open(const std::string& path, std::string& error,
                      const McapWriteOptions& options) {
  if (file_ != nullptr) {
    error = path + ": writer already open on " + path_;
    return false;
  }
  // Reset state left by an earlier file (file_ is null here, so nothing leaks).
  path_ = path;
  error_.clear();
  offset_ = 0;
  data_crc_ = summary_crc_ = 0;
  summary_ = false;
  schemas_.clear();
  channels_.clear();
  channel_counts_.clear();
  metadata_index_.clear();
  message_count_ = first_log_time_ = last_log_time_ = 0;
  // The stream is fully buffered (64 KiB): few write syscalls per control step.
  if (!out_.open(path, options.overwrite, error)) return false;
  file_ = out_.stream();
  write_raw(mcap::kMagic, sizeof mcap::kMagic, true);
  begin(mcap::Opcode::kHeader);  // spec "Header (op=0x01)": profile, library
  put_string(record_, options.profile);
  put_string(record_,
             options.library.empty() ? std::string_view(version()) : options.library);
  emit(true);
  if (!error_.empty()) {
    error = error_;
    out_.discard();  // nothing worth keeping was written
    file_ = nullptr;
    return false;
  }
  return true;
}

uint16_t McapWriter::add_schema(std::string_view name, std::string_view encoding,
                                std::string_view data) {
  if (file_ == nullptr || !error_.empty()) return fail("add_schema: writer not open"), 0;
  if (schemas_.size() >= 0xFFFF) return fail("add_schema: more than 65535 schemas"), 0;
  if (!fits_u32(name.size()) || !fits_u32(encoding.size()) || !fits_u32(data.size()))
    return fail("add_schema: field longer than 4 GiB"), 0;
  schemas_.push_back({std::string(name), std::string(encoding), std::string(data)});
  const auto id = static_cast<uint16_t>(schemas_.size());
  begin(mcap::Opcode::kSchema);  // spec "Schema (op=0x03)"; id 0 is reserved
  put_le<uint16_t>(record_, id);
  put_string(record_, name);
  put_string(record_, encoding);
  put_string(record_, data);  // uint32 length-prefixed bytes
  return emit(true) ? id : 0;
}

uint16_t McapWriter::add_channel(uint16_t schema_id, std::string_view topic,
                                 std::string_view message_encoding,
                                 const McapStringMap& metadata) {
  if (file_ == nullptr || !error_.empty()) return fail("add_channel: writer not open"), 0;
  if (schema_id > schemas_.size())
    return fail("add_channel: unknown schema id " + std::to_string(schema_id)), 0;
  if (channels_.size() >= 0xFFFF) return fail("add_channel: more than 65535 channels"), 0;
  if (!fits_u32(topic.size()) || !fits_u32(message_encoding.size()) || !map_fits(metadata))
    return fail("add_channel: field longer than 4 GiB"), 0;
  channels_.push_back({schema_id, std::string(topic), std::string(message_encoding), metadata});
  channel_counts_.push_back(0);
  // Ids start at 1 so that 0 can signal failure (0 is a valid channel id in the spec).
  const auto id = static_cast<uint16_t>(channels_.size());
  begin(mcap::Opcode::kChannel);  // spec "Channel (op=0x04)"
  put_le<uint16_t>(record_, id);
  put_le<uint16_t>(record_, schema_id);
  put_string(record_, topic);
  put_string(record_, message_encoding);
  put_string_map(record_, metadata);
  return emit(true) ? id : 0;
}

bool McapWriter::write_message(uint16_t channel_id, uint32_t sequence, uint64_t log_time_ns,
                               uint64_t publish_time_ns, std::span<const uint8_t> data) {
  if (file_ == nullptr || !error_.empty()) return fail("write_message: writer not open");
  if (channel_id == 0 || channel_id > channels_.size())
    return fail("write_message: unknown channel id " + std::to_string(channel_id));
  if (message_count_ > 0 && log_time_ns < last_log_time_)
    return fail("write_message: log time " + std::to_string(log_time_ns) + " ns on " +
                channels_[channel_id - 1].topic + " is earlier than the previous message's " +
                std::to_string(last_log_time_) + " ns (messages must be in log-time order)");
  begin(mcap::Opcode::kMessage);  // spec "Message (op=0x05)": data is the rest of the record
  put_le<uint16_t>(record_, channel_id);
  put_le<uint32_t>(record_, sequence);
  put_le<uint64_t>(record_, log_time_ns);
  put_le<uint64_t>(record_, publish_time_ns);
  record_.insert(record_.end(), data.begin(), data.end());
  if (!emit(true)) return false;
  if (message_count_ == 0) first_log_time_ = log_time_ns;
  last_log_time_ = log_time_ns;
  ++message_count_;
  ++channel_counts_[channel_id - 1];
  return true;
}

bool McapWriter::write_metadata(std::string_view name, const McapStringMap& metadata) {
  if (file_ == nullptr || !error_.empty()) return fail("write_metadata: writer not open");
  if (!fits_u32(name.size()) || !map_fits(metadata))
    return fail("write_metadata: field longer than 4 GiB");
  const uint64_t at = offset_;
  begin(mcap::Opcode::kMetadata);  // spec "Metadata (op=0x0C)"
  put_string(record_, name);
  put_string_map(record_, metadata);
  if (!emit(true)) return false;
  metadata_index_.push_back({at, offset_ - at, std::string(name)});
  return true;
}

void McapWriter::discard() {
  out_.discard();
  file_ = nullptr;
}

bool McapWriter::flush() {
  if (file_ == nullptr) return false;
  if (std::fflush(file_) != 0) return fail(tmp_path() + ": flush failed: " + std::strerror(errno));
  return error_.empty();
}

bool McapWriter::close(std::string& error) {
  if (file_ == nullptr) {
    error = error_.empty() ? std::string("close: writer not open") : error_;
    return false;
  }
  auto give_up = [&] {
    file_ = nullptr;
    const std::string note = out_.keep_partial();
    error = error_ + note;
    if (!out_.temp_path().empty())  // something was kept
      error += " (`mixpilot recover " + out_.temp_path() + "` makes a recording of its whole steps)";
    return false;
  };
  if (!error_.empty()) return give_up();

  // Data End (op=0x0F): CRC32 of all bytes before it, leading magic included.
  begin(mcap::Opcode::kDataEnd);
  put_le<uint32_t>(record_, data_crc_);
  emit(false);

  // Summary section, grouped by opcode (spec "Summary Section").
  summary_ = true;
  const uint64_t summary_start = offset_;
  struct Group {
    mcap::Opcode op;
    uint64_t start, length;
  };
  std::vector<Group> groups;
  auto group = [&](mcap::Opcode op, uint64_t start) {
    if (offset_ > start) groups.push_back({op, start, offset_ - start});
  };
  uint64_t start = offset_;
  for (std::size_t i = 0; i < schemas_.size(); ++i) {
    begin(mcap::Opcode::kSchema);
    put_le<uint16_t>(record_, static_cast<uint16_t>(i + 1));
    put_string(record_, schemas_[i].name);
    put_string(record_, schemas_[i].encoding);
    put_string(record_, schemas_[i].data);
    emit(false);
  }
  group(mcap::Opcode::kSchema, start);
  start = offset_;
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    const auto& c = channels_[i];
    begin(mcap::Opcode::kChannel);
    put_le<uint16_t>(record_, static_cast<uint16_t>(i + 1));
    put_le<uint16_t>(record_, c.schema_id);
    put_string(record_, c.topic);
    put_string(record_, c.encoding);
    put_string_map(record_, c.metadata);
    emit(false);
  }
  group(mcap::Opcode::kChannel, start);
  // Statistics (op=0x0B) after the Channel copies, as the spec requires when
  // channel_message_counts is non-empty. Every channel is listed, zero counts included.
  start = offset_;
  begin(mcap::Opcode::kStatistics);
  put_le<uint64_t>(record_, message_count_);
  put_le<uint16_t>(record_, static_cast<uint16_t>(schemas_.size()));
  put_le<uint32_t>(record_, static_cast<uint32_t>(channels_.size()));
  put_le<uint32_t>(record_, 0);  // attachments
  put_le<uint32_t>(record_, static_cast<uint32_t>(metadata_index_.size()));
  put_le<uint32_t>(record_, 0);  // chunks
  put_le<uint64_t>(record_, message_count_ ? first_log_time_ : 0);
  put_le<uint64_t>(record_, message_count_ ? last_log_time_ : 0);
  put_le<uint32_t>(record_, static_cast<uint32_t>(channels_.size() * 10));
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    put_le<uint16_t>(record_, static_cast<uint16_t>(i + 1));
    put_le<uint64_t>(record_, channel_counts_[i]);
  }
  emit(false);
  group(mcap::Opcode::kStatistics, start);
  start = offset_;
  for (const auto& m : metadata_index_) {
    begin(mcap::Opcode::kMetadataIndex);  // spec "Metadata Index (op=0x0D)"
    put_le<uint64_t>(record_, m.offset);
    put_le<uint64_t>(record_, m.length);
    put_string(record_, m.name);
    emit(false);
  }
  group(mcap::Opcode::kMetadataIndex, start);

  // Summary Offset section (op=0x0E): one record per group.
  const uint64_t summary_offset_start = offset_;
  for (const auto& g : groups) {
    begin(mcap::Opcode::kSummaryOffset);
    put_u8(record_, static_cast<uint8_t>(g.op));
    put_le<uint64_t>(record_, g.start);
    put_le<uint64_t>(record_, g.length);
    emit(false);
  }

  // Footer (op=0x02): its summary_crc covers the summary through summary_offset_start.
  begin(mcap::Opcode::kFooter);
  put_le<uint64_t>(record_, summary_start);
  put_le<uint64_t>(record_, groups.empty() ? 0 : summary_offset_start);
  const uint64_t footer_len = 8 + 8 + 4;
  std::memcpy(record_.data() + 1, &footer_len, 8);
  const uint32_t crc = crc32_update(summary_crc_, record_.data(), record_.size());
  put_le<uint32_t>(record_, crc);
  summary_ = false;
  emit(false);
  write_raw(mcap::kMagic, sizeof mcap::kMagic, false);
  if (!error_.empty()) return give_up();

  // Durable before visible (fsync, then the move); the temporary stays if either fails.
  file_ = nullptr;
  if (!out_.commit(error)) {
    fail(error);
    return false;
  }
  return true;
}

// ---- reader -----------------------------------------------------------------------------

namespace {

const char* opcode_name(uint8_t op) {
  switch (op) {
    case 0x01: return "Header";
    case 0x02: return "Footer";
    case 0x03: return "Schema";
    case 0x04: return "Channel";
    case 0x05: return "Message";
    case 0x06: return "Chunk";
    case 0x07: return "Message Index";
    case 0x08: return "Chunk Index";
    case 0x09: return "Attachment";
    case 0x0A: return "Attachment Index";
    case 0x0B: return "Statistics";
    case 0x0C: return "Metadata";
    case 0x0D: return "Metadata Index";
    case 0x0E: return "Summary Offset";
    case 0x0F: return "Data End";
    default: return "unknown";
  }
}

std::string hex2(uint8_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", v);
  return buf;
}

std::string record_desc(uint8_t op) { return std::string(opcode_name(op)) + " record (opcode " + hex2(op) + ")"; }

// Bounds-checked little-endian cursor over one record's content. All reads check the
// remaining length first; a failed read leaves the cursor unusable (ok() == false) and
// records which field failed.
class Cursor {
 public:
  Cursor(const uint8_t* base, uint64_t begin, uint64_t end) : base_(base), pos_(begin), end_(end) {}

  template <class T>
  bool get(T& v, const char* field) {
    if (!need(sizeof(T), field)) return false;
    std::memcpy(&v, base_ + pos_, sizeof(T));
    pos_ += sizeof(T);
    return true;
  }
  bool get_string(std::string& s, const char* field) {
    uint32_t n = 0;
    if (!get(n, field) || !need(n, field)) return false;
    s.assign(reinterpret_cast<const char*>(base_ + pos_), n);
    pos_ += n;
    return true;
  }
  bool get_string_map(McapStringMap& m, const char* field) {
    uint32_t n = 0;
    if (!get(n, field) || !need(n, field)) return false;
    Cursor sub(base_, pos_, pos_ + n);
    m.clear();
    while (sub.pos_ < sub.end_) {
      std::string k, v;
      if (!sub.get_string(k, field) || !sub.get_string(v, field)) return fail_at(sub);
      if (!m.emplace(std::move(k), std::move(v)).second) {
        field_ = field;
        what_ = "duplicate key";
        return ok_ = false;
      }
    }
    pos_ += n;
    return true;
  }
  template <class K, class V>
  bool get_map(std::map<K, V>& m, const char* field) {
    uint32_t n = 0;
    if (!get(n, field) || !need(n, field)) return false;
    Cursor sub(base_, pos_, pos_ + n);
    m.clear();
    while (sub.pos_ < sub.end_) {
      K k{};
      V v{};
      if (!sub.get(k, field) || !sub.get(v, field)) return fail_at(sub);
      if (!m.emplace(k, v).second) {
        field_ = field;
        what_ = "duplicate key";
        return ok_ = false;
      }
    }
    pos_ += n;
    return true;
  }

  uint64_t pos() const { return pos_; }
  uint64_t remaining() const { return end_ - pos_; }
  bool ok() const { return ok_; }
  std::string problem() const { return std::string("field '") + field_ + "' " + what_; }

 private:
  bool need(uint64_t n, const char* field) {
    if (n <= end_ - pos_) return true;
    field_ = field;
    what_ = "needs " + std::to_string(n) + " bytes, " + std::to_string(end_ - pos_) +
            " remain in the record";
    return ok_ = false;
  }
  bool fail_at(const Cursor& sub) {
    field_ = sub.field_;
    what_ = sub.what_;
    return ok_ = false;
  }

  const uint8_t* base_;
  uint64_t pos_, end_;
  bool ok_ = true;
  const char* field_ = "";
  std::string what_;
};

bool same_schema(const McapSchema& a, const McapSchema& b) {
  return a.name == b.name && a.encoding == b.encoding && a.data == b.data;
}
bool same_channel(const McapChannel& a, const McapChannel& b) {
  return a.schema_id == b.schema_id && a.topic == b.topic &&
         a.message_encoding == b.message_encoding && a.metadata == b.metadata;
}

class Parser {
 public:
  Parser(McapFile& f, std::string_view name, const McapReadOptions& o)
      : f_(f), b_(f.bytes.data()), size_(f.bytes.size()), name_(name), opt_(o) {}

  bool run(std::string& error) {
    const bool ok = parse();
    if (!ok) error = std::string(name_) + ": " + err_;
    return ok;
  }

 private:
  enum class Section { kHeader, kData, kSummary, kSummaryOffset };

  bool error_at(uint64_t at, const std::string& what) {
    err_ = what + " at byte " + std::to_string(at);
    return false;
  }
  bool error_at(uint64_t at, const std::string& what, const std::string& detail) {
    err_ = what + " at byte " + std::to_string(at) + " (" + detail + ")";
    return false;
  }
  bool malformed(uint64_t at, uint8_t op, const Cursor& c) {
    return error_at(at, "malformed " + record_desc(op), c.problem());
  }
  // A file cut short: an error, or (allow_truncated) the end of what can be recovered.
  bool truncated(uint64_t at, const std::string& what, const std::string& detail) {
    if (opt_.allow_truncated && section_ != Section::kHeader) {
      f_.complete = false;
      f_.parsed_bytes = at;  // the records before `at` are whole
      stopped_ = true;
      return true;
    }
    return error_at(at, what, detail);
  }

  bool parse() {
    if (size_ < sizeof mcap::kMagic || std::memcmp(b_, mcap::kMagic, sizeof mcap::kMagic) != 0)
      return error_at(0, "not an MCAP file: bad magic", "expected 89 4D 43 41 50 30 0D 0A");
    uint64_t pos = sizeof mcap::kMagic;
    for (;;) {
      if (pos == size_)
        return truncated(pos, "unexpected end of file", "no Footer record; the file is cut short");
      if (size_ - pos < 9)
        return truncated(pos, "truncated record",
                         "9 bytes of opcode and length needed, " + std::to_string(size_ - pos) +
                             " remain");
      const uint8_t op = b_[pos];
      // A crash can leave a zero-filled tail (blocks allocated but never written): where a
      // record should start, nothing but zeros is the end of what was written.
      if (op == 0 && opt_.allow_truncated && section_ != Section::kHeader &&
          std::all_of(b_ + pos, b_ + size_, [](uint8_t v) { return v == 0; }))
        return truncated(pos, "zero-filled tail", "");
      uint64_t len = 0;
      std::memcpy(&len, b_ + pos + 1, 8);
      if (len > size_ - pos - 9)
        return truncated(pos, "truncated record",
                         "opcode " + hex2(op) + " declares " + std::to_string(len) + " bytes, " +
                             std::to_string(size_ - pos - 9) + " remain");
      bool done = false;
      if (!record(pos, op, len, done)) return false;
      if (stopped_) return true;
      pos += 9 + len;
      if (done) {
        f_.parsed_bytes = size_;
        return finish(pos);
      }
    }
  }

  bool record(uint64_t at, uint8_t op, uint64_t len, bool& done) {
    Cursor c(b_, at + 9, at + 9 + len);
    record_end_ = at + 9 + len;
    using mcap::Opcode;
    if (section_ == Section::kHeader) {
      if (op != static_cast<uint8_t>(Opcode::kHeader))
        return error_at(at, "expected the Header record", "found " + record_desc(op));
      if (!c.get_string(f_.profile, "profile") || !c.get_string(f_.library, "library"))
        return malformed(at, op, c);
      section_ = Section::kData;
      return true;
    }
    // Opcodes this reader does not know (future or application records, 0x10-0xFF) are
    // skipped: the spec lets new records appear within the same major version.
    if (op == 0 || op > static_cast<uint8_t>(Opcode::kDataEnd)) {
      if (op == 0) return error_at(at, "invalid record opcode 0x00");
      return true;
    }
    const auto o = static_cast<Opcode>(op);
    if (o == Opcode::kHeader) return error_at(at, "second Header record");
    if (o == Opcode::kFooter) {
      if (section_ == Section::kData)
        return error_at(at, "Footer before the Data End record",
                        "the data section must end with Data End");
      return footer(at, c, done);
    }
    if (section_ == Section::kData) return data_record(at, op, c);
    return summary_record(at, op, c);
  }

  bool data_record(uint64_t at, uint8_t op, Cursor& c) {
    using mcap::Opcode;
    switch (static_cast<Opcode>(op)) {
      case Opcode::kSchema: return schema(at, op, c);
      case Opcode::kChannel: return channel(at, op, c);
      case Opcode::kMessage: return message(at, op, c);
      case Opcode::kMetadata: return metadata(at, op, c);
      case Opcode::kAttachment:
      case Opcode::kMessageIndex:
        return true;  // allowed in the data section; nothing here uses them
      case Opcode::kChunk:
        return error_at(at, "Chunk records are not supported",
                        "this reader handles unchunked files only");
      case Opcode::kDataEnd: {
        uint32_t crc = 0;
        if (!c.get(crc, "data_section_crc")) return malformed(at, op, c);
        if (crc != 0) {
          const uint32_t actual = crc32_update(0, b_, at);
          if (actual != crc)
            return error_at(at, "data section CRC mismatch",
                            "Data End stores " + std::to_string(crc) + ", bytes 0.." +
                                std::to_string(at) + " give " + std::to_string(actual));
        }
        f_.data_section_crc = crc;
        summary_begin_ = record_end_;
        section_ = Section::kSummary;
        return true;
      }
      default:
        return error_at(at, record_desc(op) + " is not allowed in the data section");
    }
  }

  bool summary_record(uint64_t at, uint8_t op, Cursor& c) {
    using mcap::Opcode;
    const auto o = static_cast<Opcode>(op);
    if (section_ == Section::kSummaryOffset && o != Opcode::kSummaryOffset)
      return error_at(at, record_desc(op) + " after the Summary Offset section began");
    if (o != Opcode::kSummaryOffset) {
      if (first_summary_ == 0) first_summary_ = at;
      // Spec: summary records are grouped by opcode; a group may not reappear.
      if (o != last_group_) {
        if (!seen_groups_.insert(op).second)
          return error_at(at, record_desc(op) + " outside its group",
                          "summary records must be grouped by opcode");
        last_group_ = o;
      }
    }
    switch (o) {
      case Opcode::kSchema: return schema(at, op, c);
      case Opcode::kChannel: return channel(at, op, c);
      case Opcode::kChunkIndex:
      case Opcode::kAttachmentIndex:
        return true;  // no chunks/attachments are read; their indexes are skipped
      case Opcode::kStatistics: return statistics(at, op, c);
      case Opcode::kMetadataIndex: return metadata_index(at, op, c);
      case Opcode::kSummaryOffset: {
        if (section_ != Section::kSummaryOffset) {
          section_ = Section::kSummaryOffset;
          first_summary_offset_ = at;
        }
        uint8_t group_op = 0;
        uint64_t start = 0, length = 0;
        if (!c.get(group_op, "group_opcode") || !c.get(start, "group_start") ||
            !c.get(length, "group_length"))
          return malformed(at, op, c);
        // The group must lie inside the summary section and start with its opcode.
        if (start < summary_begin_ || start > first_summary_offset_ ||
            length > first_summary_offset_ - start || length < 9 || b_[start] != group_op)
          return error_at(at, "Summary Offset record points outside its group",
                          "group " + hex2(group_op) + " at " + std::to_string(start) + ", " +
                              std::to_string(length) + " bytes");
        return true;
      }
      default:
        return error_at(at, record_desc(op) + " is not allowed in the summary section");
    }
  }

  bool schema(uint64_t at, uint8_t op, Cursor& c) {
    McapSchema s;
    if (!c.get(s.id, "id") || !c.get_string(s.name, "name") ||
        !c.get_string(s.encoding, "encoding") || !c.get_string(s.data, "data"))
      return malformed(at, op, c);
    if (s.id == 0) return true;  // spec: id 0 is invalid and ignored by readers
    s.record_offset = at;
    auto [it, inserted] = f_.schemas.emplace(s.id, s);
    if (!inserted && !same_schema(it->second, s))
      return error_at(at, "Schema record differs from an earlier one with the same id",
                      "id " + std::to_string(s.id));
    return true;
  }

  bool channel(uint64_t at, uint8_t op, Cursor& c) {
    McapChannel ch;
    if (!c.get(ch.id, "id") || !c.get(ch.schema_id, "schema_id") ||
        !c.get_string(ch.topic, "topic") || !c.get_string(ch.message_encoding, "message_encoding") ||
        !c.get_string_map(ch.metadata, "metadata"))
      return malformed(at, op, c);
    if (ch.schema_id != 0 && f_.schemas.count(ch.schema_id) == 0)
      return error_at(at, "Channel record references unknown schema",
                      "channel " + std::to_string(ch.id) + " '" + ch.topic + "', schema " +
                          std::to_string(ch.schema_id));
    ch.record_offset = at;
    auto [it, inserted] = f_.channels.emplace(ch.id, ch);
    if (!inserted && !same_channel(it->second, ch))
      return error_at(at, "Channel record differs from an earlier one with the same id",
                      "id " + std::to_string(ch.id));
    return true;
  }

  bool message(uint64_t at, uint8_t op, Cursor& c) {
    McapMessage m;
    if (!c.get(m.channel_id, "channel_id") || !c.get(m.sequence, "sequence") ||
        !c.get(m.log_time, "log_time") || !c.get(m.publish_time, "publish_time"))
      return malformed(at, op, c);
    if (f_.channels.count(m.channel_id) == 0)
      return error_at(at, "Message on unknown channel", "channel " + std::to_string(m.channel_id));
    if (!f_.messages.empty() && m.log_time < f_.messages.back().log_time)
      return error_at(at, "Message out of log-time order",
                      "log_time " + std::to_string(m.log_time) + " ns after " +
                          std::to_string(f_.messages.back().log_time) + " ns");
    m.record_offset = at;
    m.data_offset = c.pos();
    m.data_size = c.remaining();
    f_.messages.push_back(m);
    return true;
  }

  bool metadata(uint64_t at, uint8_t op, Cursor& c) {
    McapMetadata m;
    if (!c.get_string(m.name, "name") || !c.get_string_map(m.metadata, "metadata"))
      return malformed(at, op, c);
    m.record_offset = at;
    metadata_at_.emplace(at, f_.metadata.size());
    f_.metadata.push_back(std::move(m));
    return true;
  }

  bool statistics(uint64_t at, uint8_t op, Cursor& c) {
    if (f_.statistics) return error_at(at, "second Statistics record");
    McapStatistics s;
    if (!c.get(s.message_count, "message_count") || !c.get(s.schema_count, "schema_count") ||
        !c.get(s.channel_count, "channel_count") ||
        !c.get(s.attachment_count, "attachment_count") ||
        !c.get(s.metadata_count, "metadata_count") || !c.get(s.chunk_count, "chunk_count") ||
        !c.get(s.message_start_time, "message_start_time") ||
        !c.get(s.message_end_time, "message_end_time") ||
        !c.get_map(s.channel_message_counts, "channel_message_counts"))
      return malformed(at, op, c);
    f_.statistics = std::move(s);
    statistics_at_ = at;
    return true;
  }

  bool metadata_index(uint64_t at, uint8_t op, Cursor& c) {
    uint64_t offset = 0, length = 0;
    std::string name;
    if (!c.get(offset, "offset") || !c.get(length, "length") || !c.get_string(name, "name"))
      return malformed(at, op, c);
    // Looked up by offset: a crafted file with many Metadata and index records stays linear.
    const auto it = metadata_at_.find(offset);
    if (it == metadata_at_.end())
      return error_at(at, "Metadata Index record points to no Metadata record",
                      "'" + name + "' at " + std::to_string(offset));
    uint64_t content = 0;
    std::memcpy(&content, b_ + offset + 1, 8);
    if (f_.metadata[it->second].name != name || length != 9 + content)
      return error_at(at, "Metadata Index record does not match its Metadata record",
                      "'" + name + "' at " + std::to_string(offset));
    return true;
  }

  bool footer(uint64_t at, Cursor& c, bool& done) {
    uint64_t summary_start = 0, summary_offset_start = 0;
    uint32_t crc = 0;
    if (!c.get(summary_start, "summary_start") ||
        !c.get(summary_offset_start, "summary_offset_start") || !c.get(crc, "summary_crc"))
      return malformed(at, static_cast<uint8_t>(mcap::Opcode::kFooter), c);
    if (summary_start != first_summary_)
      return error_at(at, "Footer summary_start is wrong",
                      "says " + std::to_string(summary_start) + ", the summary starts at " +
                          std::to_string(first_summary_));
    if (summary_offset_start != first_summary_offset_)
      return error_at(at, "Footer summary_offset_start is wrong",
                      "says " + std::to_string(summary_offset_start) +
                          ", the Summary Offset section starts at " +
                          std::to_string(first_summary_offset_));
    if (crc != 0) {
      // From the start of the summary through the footer's summary_offset_start field.
      const uint32_t actual = crc32_update(0, b_ + summary_begin_, at + 1 + 8 + 16 - summary_begin_);
      if (actual != crc)
        return error_at(at, "summary CRC mismatch",
                        "Footer stores " + std::to_string(crc) + ", the summary gives " +
                            std::to_string(actual));
    }
    done = true;
    return true;
  }

  bool finish(uint64_t end) {
    // Cut inside the trailing magic: every record is whole, the file is not complete.
    if (opt_.allow_truncated && size_ - end < sizeof mcap::kMagic &&
        std::memcmp(b_ + end, mcap::kMagic, size_ - end) == 0) {
      f_.complete = false;
      f_.parsed_bytes = end;
      return true;
    }
    if (size_ - end != sizeof mcap::kMagic ||
        std::memcmp(b_ + end, mcap::kMagic, sizeof mcap::kMagic) != 0)
      return error_at(end, "expected the trailing magic after the Footer",
                      std::to_string(size_ - end) + " bytes remain");
    if (f_.statistics) {
      const auto& s = *f_.statistics;
      std::map<uint16_t, uint64_t> counts;
      for (const auto& m : f_.messages) ++counts[m.channel_id];
      bool ok = s.message_count == f_.messages.size() && s.schema_count == f_.schemas.size() &&
                s.channel_count == f_.channels.size() && s.metadata_count == f_.metadata.size() &&
                s.chunk_count == 0;
      if (!f_.messages.empty())
        ok = ok && s.message_start_time == f_.messages.front().log_time &&
             s.message_end_time == f_.messages.back().log_time;
      for (const auto& [id, n] : s.channel_message_counts) {
        auto it = counts.find(id);
        ok = ok && (it == counts.end() ? n == 0 : n == it->second);
      }
      for (const auto& [id, n] : counts)
        ok = ok && (s.channel_message_counts.empty() || s.channel_message_counts.count(id) == 1);
      if (!ok)
        return error_at(statistics_at_, "Statistics record disagrees with the data section",
                        "stated " + std::to_string(s.message_count) + " messages, found " +
                            std::to_string(f_.messages.size()));
    }
    return true;
  }

  McapFile& f_;
  const uint8_t* b_;
  uint64_t size_;
  std::string_view name_;
  McapReadOptions opt_;
  std::string err_;
  Section section_ = Section::kHeader;
  bool stopped_ = false;
  uint64_t record_end_ = 0;            // first byte after the record being parsed
  uint64_t summary_begin_ = 0;         // first byte after Data End
  uint64_t first_summary_ = 0;         // first summary record (0 = none)
  uint64_t first_summary_offset_ = 0;  // first Summary Offset record (0 = none)
  uint64_t statistics_at_ = 0;
  mcap::Opcode last_group_ = mcap::Opcode::kDataEnd;
  std::set<uint8_t> seen_groups_;
  std::map<uint64_t, std::size_t> metadata_at_;  // Metadata record offset → index in f_.metadata
};

}  // namespace

std::optional<McapFile> parse_mcap(std::vector<uint8_t> bytes, std::string_view name,
                                   std::string& error, const McapReadOptions& options) {
  McapFile f;
  f.bytes = std::move(bytes);
  Parser p(f, name, options);
  if (!p.run(error)) {
    error = escape_controls(error);  // it may quote topics and names from the file
    return std::nullopt;
  }
  return f;
}

std::optional<McapFile> read_mcap(const std::string& path, std::string& error,
                                  const McapReadOptions& options) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer before it can be refused.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    error = path + ": cannot open: " + std::strerror(errno);
    return std::nullopt;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    error = path + ": cannot read: " + std::strerror(errno);
    ::close(fd);
    return std::nullopt;
  }
  if (!S_ISREG(st.st_mode)) {
    error = path + ": not a regular file (" +
            (S_ISDIR(st.st_mode)    ? "a directory"
             : S_ISCHR(st.st_mode)  ? "a character device"
             : S_ISBLK(st.st_mode)  ? "a block device"
             : S_ISFIFO(st.st_mode) ? "a FIFO"
                                    : "a socket") +
            ")";
    ::close(fd);
    return std::nullopt;
  }
  const auto size = static_cast<uint64_t>(st.st_size);
  if (size > options.max_bytes) {
    error = path + ": " + std::to_string(size) + " bytes, more than the " +
            std::to_string(options.max_bytes) + " a recording may have";
    ::close(fd);
    return std::nullopt;
  }
  std::vector<uint8_t> bytes(static_cast<std::size_t>(size));
  std::size_t got = 0;
  int read_errno = 0;
  while (got < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + got, bytes.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) read_errno = errno;
    if (n <= 0) break;  // an error, or a file that shrank while being read
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  if (got < bytes.size()) {
    error = path + ": read failed after " + std::to_string(got) + " of " + std::to_string(size) +
            " bytes: " + (read_errno != 0 ? std::strerror(read_errno) : "the file shrank");
    return std::nullopt;
  }
  note_input_read(st, path);  // no output of this run replaces it
  return parse_mcap(std::move(bytes), path, error, options);
}

}  // namespace mixpilot
