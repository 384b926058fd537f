// MCAP container (core/recording/mcap.hpp), CRC-32 and CDR (core/recording/cdr.hpp): known vectors, exact byte
// layouts, round trips, crash behaviour, and malformed input (every truncation, random
// corruption) giving clean errors that name a byte offset.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "core/recording/cdr.hpp"
#include "core/recording/mcap.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

using test::slurp;
using test::temporaries_of;

std::vector<uint8_t> bytes_of(std::string_view s) { return {s.begin(), s.end()}; }

fs::path temp_path(const std::string& name) { return test::fresh_path("mcap", name); }

template <class T>
T get_le(const std::vector<uint8_t>& b, std::size_t at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);
  return v;
}
template <class T>
void set_le(std::vector<uint8_t>& b, std::size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof v);
}

// ---- CRC-32 -------------------------------------------------------------------------------

TEST(Crc32, KnownVectors) {
  EXPECT_EQ(crc32(bytes_of("")), 0x00000000u);
  EXPECT_EQ(crc32(bytes_of("a")), 0xE8B7BE43u);
  EXPECT_EQ(crc32(bytes_of("123456789")), 0xCBF43926u);  // the CRC-32/ISO-HDLC check value
  EXPECT_EQ(crc32(bytes_of("The quick brown fox jumps over the lazy dog")), 0x414FA339u);
  const std::vector<uint8_t> zeros(32, 0);
  EXPECT_EQ(crc32(zeros), 0x190A55ADu);
}

// The 8-byte blocks against the CRC's bitwise definition (reflected polynomial 0xEDB88320): every
// length up to 40 (whole blocks and every tail) at every alignment, random bytes, chained from a
// nonzero running value.
TEST(Crc32, MatchesTheBitwiseDefinition) {
  const auto bitwise = [](uint32_t crc, const uint8_t* p, std::size_t n) {
    uint32_t c = crc ^ 0xFFFFFFFFu;
    for (std::size_t i = 0; i < n; ++i) {
      c ^= p[i];
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? (0xEDB88320u ^ (c >> 1)) : (c >> 1);
    }
    return c ^ 0xFFFFFFFFu;
  };
  std::vector<uint8_t> b(64);
  uint32_t seed = 12345;
  for (uint8_t& x : b) x = uint8_t((seed = seed * 1103515245u + 12345u) >> 16);
  for (std::size_t offset = 0; offset < 8; ++offset)
    for (std::size_t n = 0; n <= 40; ++n) {
      EXPECT_EQ(crc32_update(0, b.data() + offset, n), bitwise(0, b.data() + offset, n)) << n;
      EXPECT_EQ(crc32_update(0xDEADBEEFu, b.data() + offset, n),
                bitwise(0xDEADBEEFu, b.data() + offset, n))
          << n;
    }
}

TEST(Crc32, IncrementalEqualsOneShot) {
  const auto b = bytes_of("The quick brown fox jumps over the lazy dog");
  for (std::size_t cut = 0; cut <= b.size(); ++cut) {
    const uint32_t a = crc32_update(0, b.data(), cut);
    EXPECT_EQ(crc32_update(a, b.data() + cut, b.size() - cut), 0x414FA339u) << cut;
  }
}

// ---- CDR ----------------------------------------------------------------------------------

std::vector<uint8_t> hdr(std::initializer_list<uint8_t> body) {
  std::vector<uint8_t> v{0x00, 0x01, 0x00, 0x00};
  v.insert(v.end(), body);
  return v;
}

TEST(Cdr, AlignmentIsRelativeToTheEndOfTheEncapsulationHeader) {
  {  // uint64 right after the header: body offset 0, no padding
    CdrWriter w;
    w.write<uint64_t>(0x0102030405060708ull);
    EXPECT_EQ(w.bytes(), hdr({8, 7, 6, 5, 4, 3, 2, 1}));
  }
  {  // uint8 then uint32: 3 bytes padding
    CdrWriter w;
    w.write<uint8_t>(1);
    w.write<uint32_t>(0x11223344u);
    EXPECT_EQ(w.bytes(), hdr({1, 0, 0, 0, 0x44, 0x33, 0x22, 0x11}));
  }
  {  // uint8 then float64: 7 bytes padding (XCDR1 aligns 8-byte types to 8)
    CdrWriter w;
    w.write<uint8_t>(1);
    w.write<double>(1.0);
    EXPECT_EQ(w.bytes(), hdr({1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xF0, 0x3F}));
  }
  {  // bool then int16: 1 byte padding
    CdrWriter w;
    w.write(true);
    w.write<int16_t>(-2);
    EXPECT_EQ(w.bytes(), hdr({1, 0, 0xFE, 0xFF}));
  }
  {  // string "ab": length 3 including NUL; the following float64 pads 1 byte to body offset 8
    CdrWriter w;
    w.write_string("ab");
    w.write<double>(-2.0);
    EXPECT_EQ(w.bytes(), hdr({3, 0, 0, 0, 'a', 'b', 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xC0}));
  }
  {  // empty string: length 1, just the NUL
    CdrWriter w;
    w.write_string("");
    EXPECT_EQ(w.bytes(), hdr({1, 0, 0, 0, 0}));
  }
  {  // uint8, int32[] {1, 2}: count aligned to 4, elements follow
    CdrWriter w;
    w.write<uint8_t>(9);
    const int32_t v[] = {1, 2};
    w.write_sequence(std::span<const int32_t>(v));
    EXPECT_EQ(w.bytes(), hdr({9, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0}));
  }
  {  // uint8, float64[] {0.5}: count at body 4, padding to 8, element at 8
    CdrWriter w;
    w.write<uint8_t>(9);
    const double v[] = {0.5};
    w.write_sequence(std::span<const double>(v));
    EXPECT_EQ(w.bytes(), hdr({9, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xE0, 0x3F}));
  }
  {  // empty float64[]: the count only, no padding for absent elements
    CdrWriter w;
    w.write<uint8_t>(9);
    w.write_sequence(std::span<const double>());
    w.write<uint8_t>(7);
    EXPECT_EQ(w.bytes(), hdr({9, 0, 0, 0, 0, 0, 0, 0, 7}));
  }
  {  // float64[2] fixed array after uint16: no count, padding to 8
    CdrWriter w;
    w.write<uint16_t>(0xABCD);
    const double v[] = {1.0, 2.0};
    w.write_array(std::span<const double>(v));
    EXPECT_EQ(w.bytes(), hdr({0xCD, 0xAB, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xF0, 0x3F, 0, 0,
                              0, 0, 0, 0, 0, 0x40}));
  }
  {  // float32[] {0.25}, int32[] {} as in sensor_msgs/Joy after a 12-byte header
    CdrWriter w;
    w.write<int32_t>(1);
    w.write<uint32_t>(2);
    w.write_string("");
    const float a[] = {0.25f};
    w.write_sequence(std::span<const float>(a));
    w.write_sequence(std::span<const int32_t>());
    EXPECT_EQ(w.bytes(), hdr({1, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0,  // sec nsec "" pad
                              1, 0, 0, 0, 0, 0, 0x80, 0x3E, 0, 0, 0, 0}));
  }
}

TEST(Cdr, ReaderRoundTripAndTruncation) {
  CdrWriter w;
  w.write<uint8_t>(200);
  w.write(true);
  w.write<int16_t>(-300);
  w.write<int64_t>(-5);
  w.write_string("héllo");
  w.write<float>(-0.0f);
  const double seq[] = {1.0, -0.0, std::numeric_limits<double>::denorm_min(), 1e308};
  w.write_sequence(std::span<const double>(seq));
  const uint32_t arr[3] = {7, 8, 9};
  w.write_array(std::span<const uint32_t>(arr));
  const auto full = w.bytes();

  for (std::size_t n = 0; n <= full.size(); ++n) {
    CdrReader r(std::span<const uint8_t>(full.data(), n));
    uint8_t u8 = 0;
    bool b = false;
    int16_t i16 = 0;
    int64_t i64 = 0;
    std::string s;
    float f = 1;
    std::vector<double> v;
    std::array<uint32_t, 3> a{};
    const bool ok = r.read(u8) && r.read(b) && r.read(i16) && r.read(i64) && r.read_string(s) &&
                    r.read(f) && r.read_sequence(v) && r.read_array(std::span<uint32_t>(a));
    if (n < full.size()) {
      EXPECT_FALSE(ok) << n;
      EXPECT_FALSE(r.ok());
      EXPECT_NE(r.error().find("at byte "), std::string::npos) << r.error();
    } else {
      ASSERT_TRUE(ok) << r.error();
      EXPECT_EQ(r.remaining(), 0u);
      EXPECT_EQ(u8, 200);
      EXPECT_TRUE(b);
      EXPECT_EQ(i16, -300);
      EXPECT_EQ(i64, -5);
      EXPECT_EQ(s, "héllo");
      EXPECT_TRUE(std::signbit(f));
      ASSERT_EQ(v.size(), 4u);
      EXPECT_EQ(std::memcmp(v.data(), seq, sizeof seq), 0);
      EXPECT_EQ(a, (std::array<uint32_t, 3>{7, 8, 9}));
    }
  }
}

TEST(Cdr, ReaderRejectsBadInput) {
  {
    const std::vector<uint8_t> be{0x00, 0x00, 0x00, 0x00, 1, 2, 3, 4};  // CDR_BE
    CdrReader r(be);
    uint32_t v;
    EXPECT_FALSE(r.read(v));
    EXPECT_NE(r.error().find("encapsulation"), std::string::npos);
  }
  {  // sequence count far beyond the data: error, and no huge allocation
    auto b = hdr({0xFF, 0xFF, 0xFF, 0x7F, 1, 2, 3, 4});
    CdrReader r(b);
    std::vector<double> v;
    EXPECT_FALSE(r.read_sequence(v));
    EXPECT_NE(r.error().find("at byte 4"), std::string::npos) << r.error();
  }
  {  // string without its NUL
    auto b = hdr({2, 0, 0, 0, 'a', 'b'});
    CdrReader r(b);
    std::string s;
    EXPECT_FALSE(r.read_string(s));
    EXPECT_NE(r.error().find("NUL"), std::string::npos);
  }
  {  // bool other than 0/1
    auto b = hdr({2});
    CdrReader r(b);
    bool v;
    EXPECT_FALSE(r.read(v));
  }
}

// ---- MCAP writer and reader -----------------------------------------------------------------

// A small file with two schemas, three channels (one without schema), metadata, messages.
fs::path write_sample(const std::string& name, int messages = 5) {
  const fs::path p = temp_path(name);
  McapWriter w;
  std::string err;
  EXPECT_TRUE(w.open(p.string(), err, {.library = "test-lib"})) << err;
  const uint16_t s1 = w.add_schema("pkg/msg/A", "ros2msg", "float64 x\n");
  const uint16_t s2 = w.add_schema("pkg/msg/B", "ros2msg", "string s\n");
  EXPECT_EQ(s1, 1);
  EXPECT_EQ(s2, 2);
  const uint16_t c1 = w.add_channel(s1, "/a", "cdr", {{"offered_qos_profiles", ""}});
  const uint16_t c2 = w.add_channel(s2, "/b", "cdr", {});
  const uint16_t c3 = w.add_channel(0, "/raw", "x-raw", {{"k", "v"}, {"k2", "v2"}});
  EXPECT_TRUE(w.write_metadata("info", {{"seed", "42"}, {"text", "line1\nline2"}}));
  for (int i = 0; i < messages; ++i) {
    const std::vector<uint8_t> data(static_cast<std::size_t>(i) + 1, static_cast<uint8_t>(i));
    EXPECT_TRUE(w.write_message(i % 2 ? c2 : c1, i, 1000u * i, 1000u * i + 1, data));
    if (i == 2) {
      EXPECT_TRUE(w.write_message(c3, 0, 2000, 1, {}));
    }
  }
  EXPECT_TRUE(w.write_metadata("second", {}));
  EXPECT_TRUE(w.close(err)) << err;
  return p;
}

TEST(Mcap, WriteReadRoundTrip) {
  const fs::path p = write_sample("roundtrip.mcap");
  EXPECT_TRUE(fs::exists(p));
  EXPECT_TRUE(temporaries_of(p).empty());
  std::string err;
  const auto f = read_mcap(p.string(), err);
  ASSERT_TRUE(f) << err;
  EXPECT_TRUE(f->complete);
  EXPECT_EQ(f->profile, "ros2");
  EXPECT_EQ(f->library, "test-lib");
  ASSERT_EQ(f->schemas.size(), 2u);
  EXPECT_EQ(f->schemas.at(1).name, "pkg/msg/A");
  EXPECT_EQ(f->schemas.at(1).encoding, "ros2msg");
  EXPECT_EQ(f->schemas.at(2).data, "string s\n");
  ASSERT_EQ(f->channels.size(), 3u);
  EXPECT_EQ(f->channels.at(3).schema_id, 0);
  EXPECT_EQ(f->channels.at(3).message_encoding, "x-raw");
  EXPECT_EQ(f->channels.at(3).metadata, (McapStringMap{{"k", "v"}, {"k2", "v2"}}));
  ASSERT_EQ(f->messages.size(), 6u);
  const auto& m = f->messages[4];  // i = 3 after the extra /raw message
  EXPECT_EQ(m.channel_id, 2);
  EXPECT_EQ(m.sequence, 3u);
  EXPECT_EQ(m.log_time, 3000u);
  EXPECT_EQ(m.publish_time, 3001u);
  EXPECT_EQ(std::vector<uint8_t>(f->data(m).begin(), f->data(m).end()),
            std::vector<uint8_t>(4, 3));
  EXPECT_EQ(f->data(f->messages[3]).size(), 0u);
  ASSERT_EQ(f->metadata.size(), 2u);
  EXPECT_EQ(f->metadata[0].name, "info");
  EXPECT_EQ(f->metadata[0].metadata.at("text"), "line1\nline2");
  ASSERT_TRUE(f->statistics);
  EXPECT_EQ(f->statistics->message_count, 6u);
  EXPECT_EQ(f->statistics->message_start_time, 0u);
  EXPECT_EQ(f->statistics->message_end_time, 4000u);
  EXPECT_EQ(f->statistics->channel_message_counts,
            (std::map<uint16_t, uint64_t>{{1, 3}, {2, 2}, {3, 1}}));
  EXPECT_NE(f->data_section_crc, 0u);
}

TEST(Mcap, LayoutFollowsTheSpec) {
  const fs::path p = write_sample("layout.mcap");
  const auto b = slurp(p);
  ASSERT_GT(b.size(), 16u + 29u);
  EXPECT_EQ(std::memcmp(b.data(), mcap::kMagic, 8), 0);
  EXPECT_EQ(std::memcmp(b.data() + b.size() - 8, mcap::kMagic, 8), 0);
  EXPECT_EQ(b[8], 0x01);  // Header first
  // Footer: opcode 0x02, length 20, then summary_start, summary_offset_start, summary_crc.
  const std::size_t footer = b.size() - 8 - 29;
  EXPECT_EQ(b[footer], 0x02);
  EXPECT_EQ(get_le<uint64_t>(b, footer + 1), 20u);
  const auto summary_start = get_le<uint64_t>(b, footer + 9);
  const auto summary_offset_start = get_le<uint64_t>(b, footer + 17);
  const auto summary_crc = get_le<uint32_t>(b, footer + 25);
  // Data End (13 bytes) just before the summary; its CRC covers every byte before it.
  const std::size_t data_end = summary_start - 13;
  EXPECT_EQ(b[data_end], 0x0F);
  EXPECT_EQ(get_le<uint32_t>(b, data_end + 9), crc32_update(0, b.data(), data_end));
  EXPECT_EQ(summary_crc,
            crc32_update(0, b.data() + summary_start, footer + 1 + 8 + 16 - summary_start));
  // Summary groups in order Schema, Channel, Statistics, Metadata Index; one Summary Offset each.
  EXPECT_EQ(b[summary_start], 0x03);
  std::vector<uint8_t> groups;
  for (std::size_t at = summary_offset_start; at < footer; at += 9 + 17) {
    ASSERT_EQ(b[at], 0x0E);
    groups.push_back(b[at + 9]);
    const auto start = get_le<uint64_t>(b, at + 10);
    EXPECT_EQ(b[start], b[at + 9]);
  }
  EXPECT_EQ(groups, (std::vector<uint8_t>{0x03, 0x04, 0x0B, 0x0D}));
}

TEST(Mcap, EmptyFileAndHandBuiltMinimalFile) {
  const fs::path p = temp_path("empty.mcap");
  McapWriter w;
  std::string err;
  ASSERT_TRUE(w.open(p.string(), err));
  ASSERT_TRUE(w.close(err)) << err;
  auto f = read_mcap(p.string(), err);
  ASSERT_TRUE(f) << err;
  EXPECT_TRUE(f->messages.empty());
  EXPECT_EQ(f->library.rfind("mixpilot ", 0), 0u);  // version() by default
  EXPECT_EQ(f->statistics->message_start_time, 0u);

  // The spec's smallest file, assembled by hand: magic, Header, Data End, Footer, magic.
  std::vector<uint8_t> b(mcap::kMagic, mcap::kMagic + 8);
  auto rec = [&](uint8_t op, std::vector<uint8_t> content) {
    b.push_back(op);
    const uint64_t n = content.size();
    b.insert(b.end(), reinterpret_cast<const uint8_t*>(&n), reinterpret_cast<const uint8_t*>(&n) + 8);
    b.insert(b.end(), content.begin(), content.end());
  };
  rec(0x01, std::vector<uint8_t>(8, 0));   // profile "", library ""
  rec(0x0F, std::vector<uint8_t>(4, 0));   // no data CRC
  rec(0x02, std::vector<uint8_t>(20, 0));  // no summary, no CRC
  b.insert(b.end(), mcap::kMagic, mcap::kMagic + 8);
  f = parse_mcap(b, "minimal", err);
  ASSERT_TRUE(f) << err;
  EXPECT_TRUE(f->schemas.empty());
  EXPECT_FALSE(f->statistics);
}

TEST(Mcap, TmpFileUntilCloseAndKeptOnFailure) {
  const fs::path p = temp_path("crash.mcap");
  std::string tmp;
  {
    McapWriter w;
    std::string err;
    ASSERT_TRUE(w.open(p.string(), err));
    tmp = w.tmp_path();
    // A unique temporary beside the target: "<target>.XXXXXX.tmp".
    ASSERT_EQ(temporaries_of(p), std::vector<fs::path>{fs::path(tmp)});
    const auto c = w.add_channel(w.add_schema("pkg/msg/A", "ros2msg", "uint8 x\n"), "/a", "cdr");
    for (uint32_t i = 0; i < 10; ++i) ASSERT_TRUE(w.write_message(c, i, i, i, std::vector<uint8_t>{1, 2}));
    EXPECT_FALSE(fs::exists(p));
  }  // destroyed without close(): a crashed or failed session
  EXPECT_FALSE(fs::exists(p));
  EXPECT_TRUE(fs::exists(tmp));
  std::string err;
  EXPECT_FALSE(read_mcap(tmp, err));
  EXPECT_NE(err.find("unexpected end of file at byte"), std::string::npos) << err;
  McapReadOptions lenient;
  lenient.allow_truncated = true;
  const auto f = read_mcap(tmp, err, lenient);
  ASSERT_TRUE(f) << err;
  EXPECT_FALSE(f->complete);
  EXPECT_EQ(f->messages.size(), 10u);  // nothing written is lost
}

TEST(Mcap, WriterRejectsMisuse) {
  const fs::path p = temp_path("misuse.mcap");
  McapWriter w;
  std::string err;
  ASSERT_TRUE(w.open(p.string(), err));
  EXPECT_EQ(w.add_channel(5, "/a", "cdr"), 0);  // unknown schema
  EXPECT_FALSE(w.close(err));
  EXPECT_NE(err.find("unknown schema id 5"), std::string::npos) << err;
  EXPECT_NE(err.find("kept in " + w.tmp_path()), std::string::npos) << err;
  EXPECT_TRUE(fs::exists(w.tmp_path()));
  EXPECT_FALSE(fs::exists(p));

  McapWriter w2;
  ASSERT_TRUE(w2.open(p.string(), err));
  const auto c = w2.add_channel(0, "/a", "x");
  EXPECT_TRUE(w2.write_message(c, 0, 100, 100, {}));
  EXPECT_FALSE(w2.write_message(c, 1, 99, 99, {}));  // log time going back
  EXPECT_FALSE(w2.write_message(c, 2, 200, 200, {}));  // sticky
  EXPECT_FALSE(w2.close(err));
  EXPECT_NE(err.find("log-time order"), std::string::npos) << err;

  McapWriter w3;
  EXPECT_FALSE(w3.open("/nonexistent-dir/x.mcap", err));
  EXPECT_EQ(err, "/nonexistent-dir/x.mcap: cannot create a file in /nonexistent-dir: " +
                     std::string(std::strerror(ENOENT)));
  EXPECT_FALSE(w3.is_open());
}

// The writer goes through OutputFile (core/base/output_file.hpp): it never replaces a
// device or an existing file it was not allowed to, and of two writers of one path the second
// to finish fails and keeps its data.
TEST(Mcap, WriterNeverClobbers) {
  std::string err;
  {  // the device node that `--record /dev/full` once replaced (as root)
    McapWriter w;
    McapWriteOptions o;
    o.overwrite = true;
    EXPECT_FALSE(w.open("/dev/full", err, o));
    EXPECT_EQ(err, "/dev/full: not a regular file (a character device)");
    EXPECT_TRUE(fs::is_character_file("/dev/full"));
  }
  const fs::path p = temp_path("existing.mcap");
  { std::ofstream(p) << "precious"; }
  {
    McapWriter w;
    EXPECT_FALSE(w.open(p.string(), err));
    EXPECT_EQ(err, p.string() + ": " + std::strerror(EEXIST) + " (refusing to overwrite it)");
    EXPECT_TRUE(temporaries_of(p).empty());
  }
  EXPECT_EQ(slurp(p), bytes_of("precious"));
  {
    McapWriter w;
    McapWriteOptions o;
    o.overwrite = true;
    ASSERT_TRUE(w.open(p.string(), err, o)) << err;
    EXPECT_EQ(slurp(p), bytes_of("precious"));  // untouched until close()
    ASSERT_TRUE(w.close(err)) << err;
  }
  EXPECT_TRUE(read_mcap(p.string(), err)) << err;

  const fs::path q = temp_path("race.mcap");
  McapWriter first, second;
  ASSERT_TRUE(first.open(q.string(), err)) << err;
  ASSERT_TRUE(second.open(q.string(), err)) << err;
  EXPECT_NE(first.tmp_path(), second.tmp_path());
  const auto c1 = first.add_channel(0, "/first", "x");
  const auto c2 = second.add_channel(0, "/second", "x");
  ASSERT_TRUE(first.write_message(c1, 0, 1, 1, std::vector<uint8_t>{1}));
  ASSERT_TRUE(second.write_message(c2, 0, 1, 1, std::vector<uint8_t>{2}));
  ASSERT_TRUE(first.close(err)) << err;
  const std::string second_tmp = second.tmp_path();
  EXPECT_FALSE(second.close(err));
  EXPECT_NE(err.find(q.string() + ": " + std::strerror(EEXIST)), std::string::npos) << err;
  EXPECT_NE(err.find("kept in " + second_tmp), std::string::npos) << err;
  const auto f = read_mcap(q.string(), err);
  ASSERT_TRUE(f) << err;
  EXPECT_EQ(f->channels.at(1).topic, "/first");
  const auto g = read_mcap(second_tmp, err);  // complete: only the final move was refused
  ASSERT_TRUE(g) << err;
  EXPECT_EQ(g->channels.at(1).topic, "/second");
}

// Inputs that are not regular files are refused at once (a FIFO without a writer would block
// a plain open(); /dev/zero never ends), and so are files over the size limit.
TEST(Mcap, ReaderRefusesSpecialFilesAndHugeFiles) {
  std::string err;
  EXPECT_FALSE(read_mcap("/dev/zero", err));
  EXPECT_EQ(err, "/dev/zero: not a regular file (a character device)");
  const fs::path dir = temp_path("a_directory.mcap");
  fs::create_directories(dir);
  EXPECT_FALSE(read_mcap(dir.string(), err));
  EXPECT_EQ(err, dir.string() + ": not a regular file (a directory)");
  const fs::path fifo = temp_path("fifo.mcap");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  EXPECT_FALSE(read_mcap(fifo.string(), err));
  EXPECT_EQ(err, fifo.string() + ": not a regular file (a FIFO)");
  EXPECT_FALSE(read_mcap(temp_path("absent.mcap").string(), err));
  EXPECT_NE(err.find(std::strerror(ENOENT)), std::string::npos) << err;

  const fs::path p = write_sample("limit.mcap");
  const auto size = fs::file_size(p);
  McapReadOptions o;
  o.max_bytes = size;
  EXPECT_TRUE(read_mcap(p.string(), err, o)) << err;
  o.max_bytes = size - 1;
  EXPECT_FALSE(read_mcap(p.string(), err, o));
  EXPECT_EQ(err, p.string() + ": " + std::to_string(size) + " bytes, more than the " +
                     std::to_string(size - 1) + " a recording may have");
}

// A crash can leave zeros where the file system had allocated blocks: lenient reading stops
// there; strict reading and zeros before a real record are errors.
TEST(Mcap, ZeroFilledTailEndsALenientRead) {
  const auto good = slurp(write_sample("zeros.mcap"));
  std::size_t at = 8;  // the start of the third Message record
  for (int seen = 0; seen < 3; at += 9 + get_le<uint64_t>(good, at + 1))
    if (good[at] == 0x05 && ++seen == 3) break;
  std::vector<uint8_t> b(good.begin(), good.begin() + std::ptrdiff_t(at));
  b.resize(b.size() + 4096, 0);
  McapReadOptions lenient;
  lenient.allow_truncated = true;
  std::string err;
  const auto f = parse_mcap(b, "z.mcap", err, lenient);
  ASSERT_TRUE(f) << err;
  EXPECT_FALSE(f->complete);
  EXPECT_EQ(f->messages.size(), 2u);
  EXPECT_EQ(f->parsed_bytes, at);
  EXPECT_FALSE(parse_mcap(b, "z.mcap", err));
  EXPECT_EQ(err, "z.mcap: invalid record opcode 0x00 at byte " + std::to_string(at));
  b.push_back(1);  // not all zeros: corruption, not a tail
  EXPECT_FALSE(parse_mcap(b, "z.mcap", err, lenient));
  EXPECT_EQ(err, "z.mcap: invalid record opcode 0x00 at byte " + std::to_string(at));
}

TEST(Mcap, ReaderErrorsNameTheByteOffset) {
  const fs::path p = write_sample("errors.mcap");
  const auto good = slurp(p);
  std::string err;
  ASSERT_TRUE(parse_mcap(good, "rec.mcap", err)) << err;

  {  // bad magic
    auto b = good;
    b[1] = 'X';
    EXPECT_FALSE(parse_mcap(b, "rec.mcap", err));
    EXPECT_EQ(err.rfind("rec.mcap: not an MCAP file: bad magic at byte 0", 0), 0u) << err;
  }
  // Find the first Message record by walking the records.
  std::size_t at = 8;
  while (good[at] != 0x05) at += 9 + get_le<uint64_t>(good, at + 1);
  {  // a record whose length runs past the end of the file
    auto b = good;
    set_le<uint64_t>(b, at + 1, 1'000'000);
    EXPECT_FALSE(parse_mcap(b, "rec.mcap", err));
    const std::string want = "rec.mcap: truncated record at byte " + std::to_string(at) +
                             " (opcode 0x05 declares 1000000 bytes, " +
                             std::to_string(good.size() - at - 9) + " remain)";
    EXPECT_EQ(err, want);
  }
  {  // a flipped payload byte: the data CRC catches it, at the Data End record
    auto b = good;
    b[at + 9 + 22] ^= 0x40;
    EXPECT_FALSE(parse_mcap(b, "rec.mcap", err));
    EXPECT_NE(err.find("data section CRC mismatch at byte"), std::string::npos) << err;
  }
  {  // a flipped summary byte: the summary CRC catches it
    auto b = good;
    const std::size_t footer = b.size() - 8 - 29;
    const auto summary_start = get_le<uint64_t>(b, footer + 9);
    b[summary_start + 12] ^= 0x01;
    EXPECT_FALSE(parse_mcap(b, "rec.mcap", err));
    EXPECT_NE(err.find("at byte"), std::string::npos) << err;
  }
  {  // message on a channel that does not exist (CRC disabled to reach the check)
    auto b = good;
    set_le<uint16_t>(b, at + 9, 77);
    const std::size_t footer = b.size() - 8 - 29;
    set_le<uint32_t>(b, get_le<uint64_t>(b, footer + 9) - 4, 0);
    EXPECT_FALSE(parse_mcap(b, "rec.mcap", err));
    EXPECT_EQ(err, "rec.mcap: Message on unknown channel at byte " + std::to_string(at) +
                       " (channel 77)");
  }
  {  // trailing garbage after the magic
    auto b = good;
    b.push_back(0);
    EXPECT_FALSE(parse_mcap(b, "rec.mcap", err));
    EXPECT_NE(err.find("at byte"), std::string::npos) << err;
  }
}

// Zeroes the data and summary CRCs so that corrupted bytes reach the parser's other checks.
std::vector<uint8_t> without_crcs(std::vector<uint8_t> b) {
  const std::size_t footer = b.size() - 8 - 29;
  const auto summary_start = get_le<uint64_t>(b, footer + 9);
  set_le<uint32_t>(b, summary_start - 4, 0);
  set_le<uint32_t>(b, footer + 25, 0);
  return b;
}

TEST(Mcap, TruncationAtEveryOffsetIsACleanError) {
  const auto good = slurp(write_sample("trunc.mcap"));
  McapReadOptions lenient;
  lenient.allow_truncated = true;
  std::size_t recovered_messages = 0;
  for (std::size_t n = 0; n < good.size(); ++n) {
    std::string err;
    const std::vector<uint8_t> b(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
    ASSERT_FALSE(parse_mcap(b, "t.mcap", err)) << n;
    ASSERT_NE(err.find(" at byte "), std::string::npos) << n << ": " << err;
    ASSERT_EQ(err.rfind("t.mcap: ", 0), 0u) << err;
    // Lenient reading recovers every complete record of a prefix (or fails on the magic
    // and Header, which must be whole).
    const auto f = parse_mcap(b, "t.mcap", err, lenient);
    if (f) {
      EXPECT_FALSE(f->complete);
      EXPECT_GE(f->messages.size(), recovered_messages) << n;
      recovered_messages = f->messages.size();
    }
  }
  EXPECT_EQ(recovered_messages, 6u);
  // parsed_bytes: the end of the last whole record, so the prefix up to it parses the same.
  for (std::size_t n = 8; n < good.size(); n += 7) {
    std::string err;
    const std::vector<uint8_t> b(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
    const auto f = parse_mcap(b, "t.mcap", err, lenient);
    if (!f) continue;
    ASSERT_LE(f->parsed_bytes, n);
    const std::vector<uint8_t> head(b.begin(), b.begin() + std::ptrdiff_t(f->parsed_bytes));
    const auto g = parse_mcap(head, "t.mcap", err, lenient);
    ASSERT_TRUE(g) << err;
    EXPECT_EQ(g->messages.size(), f->messages.size()) << n;
    EXPECT_EQ(g->parsed_bytes, f->parsed_bytes) << n;
  }
}

TEST(Mcap, RandomCorruptionNeverCrashes) {
  const auto good = without_crcs(slurp(write_sample("fuzz.mcap")));
  std::string err;
  ASSERT_TRUE(parse_mcap(good, "f.mcap", err)) << err;
  std::mt19937 rng(12345);
  int errors = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    auto b = good;
    const int flips = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < flips; ++k) {
      const std::size_t at = rng() % b.size();
      b[at] = (trial % 3 == 0) ? static_cast<uint8_t>(rng()) : static_cast<uint8_t>(b[at] ^ (1u << (rng() % 8)));
    }
    McapReadOptions o;
    o.allow_truncated = trial % 2 == 0;
    const auto f = parse_mcap(b, "f.mcap", err, o);
    if (!f) {
      ++errors;
      ASSERT_NE(err.find(" at byte "), std::string::npos) << err;
    } else {
      for (const auto& m : f->messages) ASSERT_LE(m.data_offset + m.data_size, f->bytes.size());
    }
  }
  EXPECT_GT(errors, 1000);  // most corruptions are detected even without CRCs
}

}  // namespace
}  // namespace mixpilot
