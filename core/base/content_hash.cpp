#include "core/base/content_hash.hpp"

#include <openssl/evp.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

namespace mixpilot {

namespace {

struct CtxFree {
  void operator()(EVP_MD_CTX* c) const { EVP_MD_CTX_free(c); }
};
struct FileClose {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

std::string hex(const unsigned char* d, unsigned n) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string out(2 * std::size_t(n), '0');
  for (unsigned i = 0; i < n; ++i) {
    out[2 * i] = digits[d[i] >> 4];
    out[2 * i + 1] = digits[d[i] & 15];
  }
  return out;
}

}  // namespace

std::string sha256_hex(std::string_view bytes) {
  unsigned char d[EVP_MAX_MD_SIZE];
  unsigned n = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), d, &n, EVP_sha256(), nullptr) != 1) return {};
  return hex(d, n);
}

std::optional<std::string> sha256_file(const std::string& path, std::string& error) {
  std::unique_ptr<std::FILE, FileClose> f(std::fopen(path.c_str(), "rb"));
  if (!f) {
    error = path + ": " + std::strerror(errno);
    return std::nullopt;
  }
  std::unique_ptr<EVP_MD_CTX, CtxFree> ctx(EVP_MD_CTX_new());
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1) {
    error = path + ": SHA-256 is not available (OpenSSL)";
    return std::nullopt;
  }
  std::string block(1 << 16, '\0');
  for (;;) {
    const std::size_t got = std::fread(block.data(), 1, block.size(), f.get());
    if (got > 0 && EVP_DigestUpdate(ctx.get(), block.data(), got) != 1) {
      error = path + ": SHA-256 failed (OpenSSL)";
      return std::nullopt;
    }
    if (got < block.size()) break;
  }
  if (std::ferror(f.get())) {
    error = path + ": read error: " + std::strerror(errno);
    return std::nullopt;
  }
  unsigned char d[EVP_MAX_MD_SIZE];
  unsigned n = 0;
  if (EVP_DigestFinal_ex(ctx.get(), d, &n) != 1) {
    error = path + ": SHA-256 failed (OpenSSL)";
    return std::nullopt;
  }
  return hex(d, n);
}

}  // namespace mixpilot
