#pragma once
// Test-only ToolModel for the rig tests that need one or two tools and a force law known in
// closed form: each tool is held by a linear spring to its rest point,
//   F_i = -k (x_i - r_i)                                   [N],
// the elastic grasp of a stylus on a block (for clay_tear, k is Mindlin's tangential stiffness
// of a bonded circular contact, k = 8 G a / (2 - nu), G = E / (2 (1 + nu)); Johnson, Contact
// Mechanics, 1985, §7.2). It allocates nothing in step() and returns finite forces for finite
// input (a non-finite position gives a zero force).

#include "realtime/tool_model.hpp"

#include <Eigen/Core>

#include <array>
#include <string_view>

namespace kerf::test {

class RestPointSpring final : public ToolModel {
public:
  RestPointSpring(double stiffness, std::array<Eigen::Vector3d, 2> rest, int tools)
      : m_k(stiffness), m_rest(rest), m_tools(tools) {}
  [[nodiscard]] std::string_view name() const override { return "rest-point-spring"; }
  [[nodiscard]] int tool_count() const override { return m_tools; }
  void reset() override {}
  void step(std::span<const ToolState> tools, double, std::span<ForceSample> forces) noexcept override {
    for (std::size_t i = 0; i < tools.size(); ++i) {
      const Eigen::Vector3d d = tools[i].position - m_rest[i];
      forces[i].force = d.allFinite() ? Eigen::Vector3d(-m_k * d) : Eigen::Vector3d::Zero();
      forces[i].mode = d.isZero() ? InteractionMode::no_contact : InteractionMode::deformation_1;
    }
  }

private:
  double m_k;
  std::array<Eigen::Vector3d, 2> m_rest;
  int m_tools;
};

} // namespace kerf::test
