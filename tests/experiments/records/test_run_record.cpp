// The records of a run: the content hash, SHA-256, against FIPS 180-4's published test vector.

#include "experiments/records/content_hash.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

TEST(RunRecord, Sha256MatchesFips180Vector) {
  // FIPS 180-4 example: SHA-256("abc").
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "kerf_test_run_record_abc.txt";
  std::ofstream(file, std::ios::binary) << "abc";
  EXPECT_EQ(kerf::file_sha256(file), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  std::filesystem::remove(file);
}
