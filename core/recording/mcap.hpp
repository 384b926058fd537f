#pragma once
// MCAP container files (https://mcap.dev/spec, major version 0): a generic, unchunked,
// uncompressed writer and a validating reader. Session recordings (core/recording/recording.hpp) put
// ros2-profile messages in them; any MCAP tool (Foxglove, `mcap` CLI, rosbag2) can open them.
//
// Layout written (spec "File Structure", "Multiple Messages with Summary Data"):
//
//   <Magic><Header>                                   profile, library
//   <Schema|Channel|Message|Metadata>...              data section, in the order of the calls
//   <DataEnd>                                         CRC32 of every byte before it
//   <Schema>... <Channel>... <Statistics> <MetadataIndex>...   summary section, grouped by opcode
//   <SummaryOffset>...                                one per non-empty summary group
//   <Footer><Magic>                                   summary_start, summary_offset_start, CRC
//
// Messages are not put in Chunks (no compression, no Chunk/MessageIndex/ChunkIndex records):
// a recording is appended as the session runs and readers here read the whole file anyway.
// Indexed readers that seek by time therefore find no chunk index and fall back to a linear
// scan (the TypeScript McapStreamReader, `mcap cat`), which is fine for training sessions.
//
// Crash safety: the writer streams to a temporary beside <path>, "<path>.XXXXXX.tmp"
// (core/base/output_file.hpp), and moves it to <path> only in close(), so <path> is either
// absent (or its old contents, when overwriting) or a complete file. A session that fails keeps
// its temporary, which read_mcap with allow_truncated reads up to the last complete record.
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/output_file.hpp"

namespace mixpilot {

// CRC-32 as used by MCAP (ISO-HDLC / zlib: reflected polynomial 0xEDB88320, initial value and
// final XOR 0xFFFFFFFF). Incremental: crc32_update(crc32_update(0, a), b) == crc32(a ++ b).
uint32_t crc32_update(uint32_t crc, const uint8_t* data, std::size_t size);
inline uint32_t crc32(std::span<const uint8_t> data) {
  return crc32_update(0, data.data(), data.size());
}

namespace mcap {
// Record opcodes (spec "Records").
enum class Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};
// 0x89 "MCAP" '0' "\r\n": the '0' is the major version.
inline constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
}  // namespace mcap

using McapStringMap = std::map<std::string, std::string>;

struct McapWriteOptions {
  bool overwrite = false;              // replace an existing regular file at the path
  std::string_view profile = "ros2";   // the spec's well-known profile
  std::string_view library = {};       // the writer's name; empty = version()
};

// Streaming writer. Not thread-safe; one writer per file. The first failure is kept (sticky):
// later calls do nothing and return false/0, and close() reports it.
class McapWriter {
 public:
  McapWriter() = default;
  // Without close() the temporary is flushed and left in place (nothing recorded is lost).
  ~McapWriter() = default;
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Checks `path` (OutputFile::open: never a device or directory, an existing file only with
  // options.overwrite), creates the temporary and writes the magic and the Header record.
  bool open(const std::string& path, std::string& error, const McapWriteOptions& options = {});

  // Writes a Schema record; returns its id (1, 2, ...) or 0 on failure.
  uint16_t add_schema(std::string_view name, std::string_view encoding, std::string_view data);
  // Writes a Channel record; returns its id (1, 2, ...) or 0 on failure. schema_id 0 = none.
  uint16_t add_channel(uint16_t schema_id, std::string_view topic,
                       std::string_view message_encoding, const McapStringMap& metadata = {});
  // Writes a Message record. log_time must not decrease from one message to the next.
  bool write_message(uint16_t channel_id, uint32_t sequence, uint64_t log_time_ns,
                     uint64_t publish_time_ns, std::span<const uint8_t> data);
  // Writes a Metadata record (indexed in the summary).
  bool write_metadata(std::string_view name, const McapStringMap& metadata);
  // Pushes buffered bytes to the OS (a crash after this loses nothing already written).
  bool flush();

  // Writes DataEnd, the summary, SummaryOffsets, Footer and magic, then moves the temporary to
  // the final path. On failure the temporary stays for inspection or recovery (unless nothing
  // of it reached the disk; the message says which).
  bool close(std::string& error);
  // Closes and removes the temporary: nothing of this file is wanted (a run that ended before
  // it began).
  void discard();

  bool is_open() const { return file_ != nullptr; }
  const std::string& error() const { return error_; }
  const std::string& path() const { return path_; }
  // The temporary being written ("<path>.XXXXXX.tmp"); kept after a failed close(), "" after
  // a successful one.
  const std::string& tmp_path() const { return out_.temp_path(); }
  uint64_t bytes_written() const { return offset_; }

 private:
  struct SchemaInfo {
    std::string name, encoding, data;
  };
  struct ChannelInfo {
    uint16_t schema_id;
    std::string topic, encoding;
    McapStringMap metadata;
  };
  struct MetadataIndexEntry {
    uint64_t offset, length;
    std::string name;
  };

  bool fail(std::string message);
  // Writes `record_` (opcode + length prefix + content) and updates offset and the data CRC.
  bool emit(bool in_data_section);
  void begin(mcap::Opcode op);
  bool write_raw(const uint8_t* data, std::size_t size, bool in_data_section);

  OutputFile out_;
  std::FILE* file_ = nullptr;  // out_.stream() while open
  std::string path_;
  std::string error_;
  uint64_t offset_ = 0;
  uint32_t data_crc_ = 0;
  uint32_t summary_crc_ = 0;
  bool summary_ = false;  // bytes go into the summary CRC (after DataEnd)
  std::vector<uint8_t> record_;  // record being built, reused (no allocation per message)
  std::vector<SchemaInfo> schemas_;    // id = index + 1
  std::vector<ChannelInfo> channels_;  // id = index + 1
  std::vector<uint64_t> channel_counts_;
  std::vector<MetadataIndexEntry> metadata_index_;
  uint64_t message_count_ = 0;
  uint64_t first_log_time_ = 0, last_log_time_ = 0;
};

// ---- reading ----------------------------------------------------------------------------

struct McapSchema {
  uint16_t id = 0;
  std::string name, encoding;
  std::string data;  // the schema text (bytes)
  uint64_t record_offset = 0;  // first Schema record with this id
};

struct McapChannel {
  uint16_t id = 0;
  uint16_t schema_id = 0;
  std::string topic, message_encoding;
  McapStringMap metadata;
  uint64_t record_offset = 0;  // first Channel record with this id
};

struct McapMessage {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0, publish_time = 0;
  uint64_t record_offset = 0;  // byte offset of the record's opcode in the file
  uint64_t data_offset = 0;    // byte offset of the message data in the file
  uint64_t data_size = 0;
};

struct McapMetadata {
  std::string name;
  McapStringMap metadata;
  uint64_t record_offset = 0;
};

struct McapStatistics {
  uint64_t message_count = 0;
  uint16_t schema_count = 0;
  uint32_t channel_count = 0, attachment_count = 0, metadata_count = 0, chunk_count = 0;
  uint64_t message_start_time = 0, message_end_time = 0;
  std::map<uint16_t, uint64_t> channel_message_counts;
};

struct McapFile {
  std::vector<uint8_t> bytes;  // the whole file; messages refer into it
  std::string profile, library;
  std::map<uint16_t, McapSchema> schemas;
  std::map<uint16_t, McapChannel> channels;
  std::vector<McapMessage> messages;  // in file order (= log-time order, checked)
  std::vector<McapMetadata> metadata;
  std::optional<McapStatistics> statistics;  // from the summary, when present
  uint32_t data_section_crc = 0;             // as stored in DataEnd (0 = not computed)
  // False only with allow_truncated, when the file ended before the Footer (a crashed
  // session's temporary); everything up to the last complete record is then returned.
  bool complete = true;
  uint64_t parsed_bytes = 0;  // end of the last complete record read (the size when complete)

  std::span<const uint8_t> data(const McapMessage& m) const {
    return {bytes.data() + m.data_offset, static_cast<std::size_t>(m.data_size)};
  }
};

struct McapReadOptions {
  bool allow_truncated = false;  // accept a file cut short (see McapFile::complete)
  // read_mcap refuses larger files: the whole file is held in memory, and decoding a
  // recording takes about as much again.
  uint64_t max_bytes = uint64_t(4) << 30;
};

// Parses and validates a whole MCAP file: magic, record framing and lengths, opcodes allowed
// in each section, schema/channel references, non-decreasing message log times, duplicate
// records identical, Statistics/MetadataIndex consistent with the data, footer offsets, and
// the data and summary CRCs when non-zero. Never throws; on failure returns nullopt and sets
// `error` to "<name>: <what> at byte <offset> (...)".
std::optional<McapFile> parse_mcap(std::vector<uint8_t> bytes, std::string_view name,
                                   std::string& error, const McapReadOptions& options = {});
// Reads the file at `path` (a regular file of at most options.max_bytes: a device, FIFO or
// directory is refused without blocking on it) and parses it as parse_mcap does.
std::optional<McapFile> read_mcap(const std::string& path, std::string& error,
                                  const McapReadOptions& options = {});

}  // namespace mixpilot
