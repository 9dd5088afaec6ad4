// The records of a run: the content hash, SHA-256, against FIPS 180-4's published test vector.

#include "experiments/records/content_hash.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace kerf;
namespace fs = std::filesystem;

namespace {
fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "kerf_test_records";
  fs::create_directories(dir);
  return dir / name;
}
} // namespace

TEST(RunRecord, Sha256MatchesFips180Vector) {
  // FIPS 180-4 example: SHA-256("abc").
  const fs::path file = scratch("abc.txt");
  {
    std::ofstream out(file, std::ios::binary);
    out << "abc";
  }
  EXPECT_EQ(file_sha256(file), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}
