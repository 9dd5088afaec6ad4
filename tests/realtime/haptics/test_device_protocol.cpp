// The device protocol's decoder (docs/device-protocol.md): byte layout, and every kind of bad
// datagram dropped and counted exactly once. Expected counts follow from the sequences fed in.

#include "realtime/haptics/device_protocol.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <vector>

using namespace kerf;

namespace {

std::vector<std::byte> state_bytes(std::uint32_t sequence, std::uint64_t timestamp, double x = 0.01) {
  DeviceStatePacket p;
  p.sequence = sequence;
  p.timestamp_ns = timestamp;
  p.position = {x, -0.02, 0.03};
  p.orientation = {std::sqrt(0.5), 0.0, std::sqrt(0.5), 0.0};
  p.buttons = 0b101;
  p.max_force = 8.5;
  std::array<std::byte, device_state_packet_size> b;
  encode(p, b);
  return {b.begin(), b.end()};
}

} // namespace

TEST(DeviceProtocol, StateLayoutIsLittleEndianAsDocumented) {
  const std::vector<std::byte> b = state_bytes(0x01020304u, 0x1122334455667788ull);
  ASSERT_EQ(b.size(), 88u);
  EXPECT_EQ(std::memcmp(b.data(), "KERF", 4), 0);
  // version 1, type 1, little-endian u16 (docs/device-protocol.md table)
  EXPECT_EQ(std::to_integer<int>(b[4]), 1);
  EXPECT_EQ(std::to_integer<int>(b[5]), 0);
  EXPECT_EQ(std::to_integer<int>(b[6]), 1);
  EXPECT_EQ(std::to_integer<int>(b[8]), 0x04); // least significant byte first
  EXPECT_EQ(std::to_integer<int>(b[11]), 0x01);
  EXPECT_EQ(std::to_integer<int>(b[12]), 0x88);
  EXPECT_EQ(std::to_integer<int>(b[19]), 0x11);
  // position x = 0.01 as IEEE 754 binary64 at offset 20
  double x = 0.0;
  std::uint64_t bits = 0;
  for (int k = 0; k < 8; ++k) bits |= static_cast<std::uint64_t>(std::to_integer<unsigned>(b[20 + k])) << (8 * k);
  std::memcpy(&x, &bits, 8);
  EXPECT_EQ(x, 0.01);
  EXPECT_EQ(std::to_integer<int>(b[76]), 0b101); // buttons at offset 20 + 24 + 32
}

TEST(DeviceProtocol, RoundTripsBothDirections) {
  DeviceStatePacket s;
  ASSERT_EQ(decode(state_bytes(7, 99), s), DecodeError::none);
  EXPECT_EQ(s.sequence, 7u);
  EXPECT_EQ(s.timestamp_ns, 99u);
  EXPECT_EQ(s.position, Eigen::Vector3d(0.01, -0.02, 0.03));
  EXPECT_EQ(s.buttons, 0b101u);
  EXPECT_EQ(s.max_force, 8.5);

  ForceCommandPacket c;
  c.sequence = 42;
  c.timestamp_ns = 1234567890123ull;
  c.echo_sequence = 41;
  c.status = safety_clamped | safety_ramping;
  c.force = {1.5, -2.25, 3.0};
  c.torque = {0.0, 0.1, 0.0};
  std::array<std::byte, force_command_packet_size> b;
  ASSERT_EQ(encode(c, b), 76u);
  ForceCommandPacket d;
  ASSERT_EQ(decode(b, d), DecodeError::none);
  EXPECT_EQ(d.sequence, 42u);
  EXPECT_EQ(d.echo_sequence, 41u);
  EXPECT_EQ(d.status, c.status);
  EXPECT_EQ(d.force, c.force);
  EXPECT_EQ(d.torque, c.torque);
}

TEST(DeviceProtocol, DecoderNamesEachDefect) {
  DeviceStatePacket s;
  std::vector<std::byte> b = state_bytes(1, 1);
  EXPECT_EQ(decode(std::span(b).first(87), s), DecodeError::wrong_size); // truncated
  std::vector<std::byte> longer = b;
  longer.push_back(std::byte{0});
  EXPECT_EQ(decode(longer, s), DecodeError::wrong_size);
  std::vector<std::byte> bad = b;
  bad[0] = std::byte{'X'};
  EXPECT_EQ(decode(bad, s), DecodeError::bad_magic);
  bad = b;
  bad[4] = std::byte{2};
  EXPECT_EQ(decode(bad, s), DecodeError::unsupported_version);
  bad = b;
  bad[6] = std::byte{2};
  EXPECT_EQ(decode(bad, s), DecodeError::wrong_type);
  bad = b;
  for (int k = 0; k < 8; ++k) bad[20 + k] = std::byte{0xFF}; // a NaN position x
  EXPECT_EQ(decode(bad, s), DecodeError::invalid_value);
  bad = b;
  bad[20 + 24 + 15] = std::byte{0x40}; // orientation x's top byte: x = 2, so |q| is far from 1
  EXPECT_EQ(decode(bad, s), DecodeError::invalid_value);
  // A force command is not a device state (size differs first).
  ForceCommandPacket c;
  std::array<std::byte, force_command_packet_size> cb;
  encode(c, cb);
  EXPECT_EQ(decode(cb, s), DecodeError::wrong_size);
}

TEST(DeviceProtocol, ReorderedDuplicatedTruncatedAndGarbageAreDroppedAndCounted) {
  SequenceFilter filter;
  LinkCounters counters;
  DeviceStatePacket out;
  std::vector<std::uint32_t> accepted;
  auto feed = [&](const std::vector<std::byte>& d) {
    if (receive_device_state(d, filter, counters, out)) accepted.push_back(out.sequence);
  };
  // Arrival order: 1 2 2(dup) 4 3(reordered: older than 4) 5 [truncated 6] [garbage] [version 9] 7
  // 7(dup) 1(very late).
  feed(state_bytes(1, 100));
  feed(state_bytes(2, 200));
  feed(state_bytes(2, 200));
  feed(state_bytes(4, 400));
  feed(state_bytes(3, 300));
  feed(state_bytes(5, 500));
  std::vector<std::byte> truncated = state_bytes(6, 600);
  truncated.resize(40);
  feed(truncated);
  std::vector<std::byte> garbage(88);
  for (std::size_t k = 0; k < garbage.size(); ++k) garbage[k] = static_cast<std::byte>(k * 37 + 11);
  feed(garbage);
  std::vector<std::byte> future = state_bytes(6, 600);
  future[4] = std::byte{9};
  feed(future);
  feed(state_bytes(7, 700));
  feed(state_bytes(7, 700));
  feed(state_bytes(1, 100));

  EXPECT_EQ(accepted, (std::vector<std::uint32_t>{1, 2, 4, 5, 7}));
  EXPECT_EQ(counters.received, 12u);
  EXPECT_EQ(counters.accepted, 5u);
  EXPECT_EQ(counters.duplicated, 2u);          // the second 2 and the second 7
  EXPECT_EQ(counters.stale, 2u);               // 3 after 4, and 1 at the end
  EXPECT_EQ(counters.malformed, 2u);           // truncated and garbage
  EXPECT_EQ(counters.unsupported_version, 1u); // version 9
  EXPECT_EQ(counters.lost, 2u);                // 3 (arrived late, dropped) and 6 never accepted
  EXPECT_EQ(counters.accepted + counters.dropped(), counters.received);
}

TEST(DeviceProtocol, SequenceNumbersMayWrap) {
  // RFC 1982: 0 is newer than 0xFFFFFFFF (difference +1), so a wrapping counter keeps working.
  SequenceFilter filter;
  LinkCounters counters;
  EXPECT_EQ(filter.admit(0xFFFFFFFEu, 1, counters), SequenceFilter::Verdict::accept);
  EXPECT_EQ(filter.admit(0xFFFFFFFFu, 2, counters), SequenceFilter::Verdict::accept);
  EXPECT_EQ(filter.admit(0u, 3, counters), SequenceFilter::Verdict::accept);
  EXPECT_EQ(filter.admit(0xFFFFFFFFu, 2, counters), SequenceFilter::Verdict::stale);
  EXPECT_EQ(counters.lost, 0u);
}

TEST(DeviceProtocol, TimestampGoingBackwardIsStale) {
  SequenceFilter filter;
  LinkCounters counters;
  EXPECT_EQ(filter.admit(10, 1000, counters), SequenceFilter::Verdict::accept);
  EXPECT_EQ(filter.admit(11, 999, counters), SequenceFilter::Verdict::stale);
  EXPECT_EQ(filter.admit(12, 1000, counters), SequenceFilter::Verdict::accept); // equal time is allowed
  EXPECT_EQ(counters.lost, 1u);                                                 // 11 was never accepted
}

TEST(DeviceProtocol, ForceCommandsAreFilteredTheSameWay) {
  SequenceFilter filter;
  LinkCounters counters;
  ForceCommandPacket out;
  auto bytes = [](std::uint32_t seq, double fx) {
    ForceCommandPacket c;
    c.sequence = seq;
    c.timestamp_ns = seq;
    c.force = {fx, 0.0, 0.0};
    std::array<std::byte, force_command_packet_size> b;
    encode(c, b);
    return b;
  };
  EXPECT_TRUE(receive_force_command(bytes(1, 1.0), filter, counters, out));
  EXPECT_FALSE(receive_force_command(bytes(1, 1.0), filter, counters, out));
  auto inf = bytes(2, std::numeric_limits<double>::infinity());
  EXPECT_FALSE(receive_force_command(inf, filter, counters, out));
  EXPECT_TRUE(receive_force_command(bytes(3, 2.0), filter, counters, out));
  EXPECT_EQ(out.force.x(), 2.0);
  EXPECT_EQ(counters.duplicated, 1u);
  EXPECT_EQ(counters.malformed, 1u);
  EXPECT_EQ(counters.accepted, 2u);
  EXPECT_EQ(counters.lost, 1u);
}
