#pragma once
// CDR serialization of ROS 2 messages (OMG CDR as used by rmw_fastrtps / rosbag2 with the
// "cdr" MCAP message encoding): XCDR1 ("plain CDR"), little-endian.
//
//   00 01 00 00            encapsulation header: CDR_LE, options 0
//   <fields...>            each primitive aligned to its own size (1, 2, 4 or 8 bytes),
//                          offsets counted from the first byte after the header
//
// string       uint32 length including the terminating NUL, the bytes, NUL
// T[] / seq    uint32 element count, then the elements (each aligned as T)
// T[N]         the N elements, no count
// bool         one byte, 0 or 1
// Nested messages are their fields in order (no extra alignment or header).
#include <bit>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace mixpilot {

static_assert(std::endian::native == std::endian::little,
              "the CDR writer/reader assume a little-endian host (CDR_LE is native)");

// Appends CDR data to a byte buffer that starts with the encapsulation header.
class CdrWriter {
 public:
  CdrWriter() { reset(); }

  // Starts a new message, keeping the buffer's capacity.
  void reset() {
    buf_.assign({0x00, 0x01, 0x00, 0x00});
  }

  template <class T>
    requires std::is_arithmetic_v<T>
  void write(T v) {
    if constexpr (std::is_same_v<T, bool>) {
      buf_.push_back(v ? 1 : 0);
    } else {
      align(sizeof(T));
      append(&v, sizeof(T));
    }
  }
  void write_string(std::string_view s) {
    write<uint32_t>(static_cast<uint32_t>(s.size() + 1));
    append(s.data(), s.size());
    buf_.push_back(0);
  }
  // string[]: count, then each string.
  void write_strings(std::span<const std::string> v) {
    write<uint32_t>(static_cast<uint32_t>(v.size()));
    for (const std::string& s : v) write_string(s);
  }
  // Unbounded or bounded sequence (T[] / T[<=N]): count, then elements.
  template <class T>
  void write_sequence(std::span<const T> v) {
    write<uint32_t>(static_cast<uint32_t>(v.size()));
    write_array(v);
  }
  // Fixed-size array (T[N]): elements only.
  template <class T>
  void write_array(std::span<const T> v) {
    if constexpr (std::is_same_v<T, bool>) {
      for (bool b : v) write(b);
    } else {
      if (v.empty()) return;
      align(sizeof(T));
      append(v.data(), v.size() * sizeof(T));
    }
  }

  const std::vector<uint8_t>& bytes() const { return buf_; }
  std::span<const uint8_t> span() const { return buf_; }

 private:
  void align(std::size_t n) {
    const std::size_t body = buf_.size() - 4;  // alignment origin: after the header
    buf_.resize(buf_.size() + (n - body % n) % n, 0);
  }
  void append(const void* p, std::size_t n) {
    const auto* b = static_cast<const uint8_t*>(p);
    buf_.insert(buf_.end(), b, b + n);
  }
  std::vector<uint8_t> buf_;
};

// Reads CDR data written as above. Every read checks the remaining bytes; the first failure
// sticks (later reads return false) and error() names the byte offset within the message.
class CdrReader {
 public:
  explicit CdrReader(std::span<const uint8_t> data) : data_(data) {
    if (data.size() < 4) {
      fail(0, "message shorter than the 4-byte encapsulation header");
    } else if (data[0] != 0x00 || data[1] != 0x01) {
      // 00 01 = CDR_LE (XCDR1). Big-endian (00 00) and XCDR2 are not produced by ROS 2 bags
      // from little-endian hosts, and are not read here.
      fail(0, "unsupported encapsulation " + hex(data[0]) + " " + hex(data[1]) +
                  " (expected 00 01, CDR little-endian)");
    } else {
      pos_ = 4;
    }
  }

  template <class T>
    requires std::is_arithmetic_v<T>
  bool read(T& v) {
    if (!ok_) return false;
    if constexpr (std::is_same_v<T, bool>) {
      uint8_t b = 0;
      if (!take(&b, 1, "bool")) return false;
      if (b > 1) return fail(pos_ - 1, "bool value " + std::to_string(b) + " is not 0 or 1");
      v = b != 0;
      return true;
    } else {
      return align(sizeof(T)) && take(&v, sizeof(T), "value");
    }
  }
  bool read_string(std::string& s) {
    uint32_t n = 0;
    if (!read(n)) return false;
    if (n == 0) {  // some writers encode "" as length 0; accept it
      s.clear();
      return true;
    }
    if (n > remaining())
      return fail(pos_ - 4, "string length " + std::to_string(n) + " exceeds the " +
                                std::to_string(remaining()) + " remaining bytes");
    if (data_[pos_ + n - 1] != 0) return fail(pos_ + n - 1, "string is not NUL-terminated");
    s.assign(reinterpret_cast<const char*>(data_.data() + pos_), n - 1);
    pos_ += n;
    return true;
  }
  bool read_strings(std::vector<std::string>& v) {
    uint32_t n = 0;
    if (!read(n)) return false;
    // Each string takes at least its 4-byte length: a corrupt count cannot allocate much.
    if (static_cast<uint64_t>(n) * 4 > remaining())
      return fail(pos_ - 4, "sequence of " + std::to_string(n) + " strings exceeds the " +
                                std::to_string(remaining()) + " remaining bytes");
    v.resize(n);
    for (std::string& s : v)
      if (!read_string(s)) return false;
    return true;
  }
  template <class T>
  bool read_sequence(std::vector<T>& v) {
    uint32_t n = 0;
    if (!read(n)) return false;
    // Check the count against the bytes left before allocating (a corrupt count must not
    // allocate gigabytes); alignment padding is at most sizeof(T) - 1.
    if (static_cast<uint64_t>(n) * sizeof(T) > remaining())
      return fail(pos_ - 4, "sequence of " + std::to_string(n) + " elements exceeds the " +
                                std::to_string(remaining()) + " remaining bytes");
    v.resize(n);
    return read_array(std::span<T>(v));
  }
  template <class T>
  bool read_array(std::span<T> v) {
    if constexpr (std::is_same_v<T, bool>) {
      for (auto& b : v)
        if (!read(b)) return false;
      return true;
    } else {
      if (v.empty()) return ok_;
      return align(sizeof(T)) && take(v.data(), v.size() * sizeof(T), "array");
    }
  }

  bool ok() const { return ok_; }
  const std::string& error() const { return error_; }
  std::size_t position() const { return pos_; }
  std::size_t remaining() const { return data_.size() - pos_; }

 private:
  static std::string hex(uint8_t v) {
    const char* d = "0123456789ABCDEF";
    return {d[v >> 4], d[v & 15]};
  }
  bool fail(std::size_t at, std::string what) {
    if (ok_) error_ = "CDR: " + what + " at byte " + std::to_string(at) + " of the message";
    ok_ = false;
    return false;
  }
  bool align(std::size_t n) {
    const std::size_t pad = (n - (pos_ - 4) % n) % n;
    if (pad > remaining())
      return fail(pos_, "truncated (alignment padding runs past the end)");
    pos_ += pad;
    return true;
  }
  bool take(void* out, std::size_t n, const char* what) {
    if (n > remaining())
      return fail(pos_, std::string("truncated ") + what + " (" + std::to_string(n) +
                            " bytes needed, " + std::to_string(remaining()) + " remain)");
    std::memcpy(out, data_.data() + pos_, n);
    pos_ += n;
    return true;
  }

  std::span<const uint8_t> data_;
  std::size_t pos_ = 0;
  bool ok_ = true;
  std::string error_;
};

}  // namespace mixpilot
