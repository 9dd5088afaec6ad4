#pragma once
// Content hashes that tie what kerf writes to what it read: the scene file's SHA-256 in every
// manifest, the study's reference cache key. Through OpenSSL (libcrypto), which only the research
// side links.

#include <filesystem>
#include <string>

namespace kerf {

/// Lower-case hex SHA-256 (FIPS 180-4, through OpenSSL) of a file's bytes, e.g. the scene file
/// hash of every manifest. Throws std::runtime_error if the file cannot be read.
std::string file_sha256(const std::filesystem::path& file);

/// Lower-case hex SHA-256 of `text` (64 digits), e.g. the study's reference cache key.
std::string text_sha256(const std::string& text);

} // namespace kerf
