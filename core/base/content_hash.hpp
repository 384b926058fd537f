#pragma once
// SHA-256 (FIPS 180-4, through OpenSSL's libcrypto) as lowercase hex: what identifies a scenario
// text, an input-settings file and a recording in the history (SPEC §10), and a branch's parent
// recording (SPEC §10, fly from here).
#include <optional>
#include <string>
#include <string_view>

namespace mixpilot {

std::string sha256_hex(std::string_view bytes);
// The file's SHA-256, read in blocks; nullopt with the reason (naming the file).
std::optional<std::string> sha256_file(const std::string& path, std::string& error);

}  // namespace mixpilot
