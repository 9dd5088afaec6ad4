#include "experiments/records/content_hash.hpp"

#include <openssl/evp.h>

#include <array>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace kerf {

namespace {

/// Lower-case hex SHA-256 of the bytes `feed(update)` passes to `update(data, size)`.
template <class Feed> std::string sha256_hex(Feed&& feed) {
  std::unique_ptr<EVP_MD_CTX, void (*)(EVP_MD_CTX*)> ctx(EVP_MD_CTX_new(), &EVP_MD_CTX_free);
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1) throw std::runtime_error("SHA-256 unavailable");
  feed([&](const char* data, std::size_t size) {
    if (EVP_DigestUpdate(ctx.get(), data, size) != 1) throw std::runtime_error("SHA-256 unavailable");
  });
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  EVP_DigestFinal_ex(ctx.get(), digest.data(), &length);
  static constexpr char hex[] = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < length; ++i) {
    out += hex[digest[i] >> 4];
    out += hex[digest[i] & 15];
  }
  return out;
}

} // namespace

std::string file_sha256(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot read to hash");
  return sha256_hex([&](auto&& update) {
    std::array<char, 65536> buffer{};
    while (in) {
      in.read(buffer.data(), buffer.size());
      if (in.gcount() > 0) update(buffer.data(), static_cast<std::size_t>(in.gcount()));
    }
  });
}

std::string text_sha256(const std::string& text) {
  return sha256_hex([&](auto&& update) { update(text.data(), text.size()); });
}

} // namespace kerf
