#pragma once
// Scene: everything a run needs to know about one experiment (../shared/DESIGN.md, "Scene"),
// read from experiments/scenes/NAME.toml. All quantities are SI: the reader converts units once.

#include "formats/trajectory/trajectory.hpp"
#include "meshes/blade_shape.hpp"
#include "meshes/material_law.hpp"
#include "realtime/fracture/fracture_response.hpp"
#include "realtime/phenomena.hpp"

#include <Eigen/Core>

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace kerf {

/// Where the body's geometry comes from: a parametric .geo (meshes/geo), a closed STL surface
/// that gmsh meshes into tetrahedra, or a ready tetrahedral .msh (checked for inverted elements
/// when it is loaded).
struct SceneGeometry {
  enum class Kind { geo, stl, msh };
  Kind kind = Kind::geo;
  std::filesystem::path source;               ///< absolute path of the .geo, .stl or .msh
  std::map<std::string, double> parameters;   ///< .geo parameters, SI
  double element_size = 0.0;                  ///< target tetrahedron size [m] > 0
  /// The finite-element reference's element degree (FE_SimplexP: 1 linear, 2 quadratic
  /// tetrahedra), a mesh choice like element_size: quadratic where linear tetrahedra lock (a nearly
  /// incompressible body strongly stretched), linear where a cohesive crack path needs many small
  /// elements. `kerf reference` and a study use it unless told otherwise.
  int element_degree = 1;
  /// The element size the scene file gives [m] (0: as element_size). A run that meshes the scene at
  /// another element size (a study's mesh level, `--element-size`) scales every size the mesh is
  /// graded to (scene_mesh_parameters) by element_size / nominal_element_size, so that a level is
  /// the same graded mesh, systematically refined.
  double nominal_element_size = 0.0;
  /// The grasp rims' element size in the reference's mesh instead of the one derived from the
  /// scene (scene_mesh_parameters; `kerf reference --grasp-element-size`): for a study of the
  /// rim's resolution. Not a scene-file key.
  std::optional<double> grasp_element_size;
  double stl_scale = 1.0;                     ///< STL coordinates times this = metres
};

/// MaterialLaw: the hyperelastic law the reference solves with (meshes/material_law.hpp).

/// The scene file's name of `law` ("neo-hookean", "decoupled-neo-hookean", "st-venant-kirchhoff").
const char* material_law_name(MaterialLaw law);

/// Material of the body or of one layer. Literature names; SI units.
struct Material {
  std::string region;                 ///< physical volume it applies to ("body" for the base material)
  MaterialLaw law = MaterialLaw::neo_hookean;
  double youngs_modulus = 0.0;        ///< E [Pa] > 0
  double poisson_ratio = 0.0;         ///< ν in (-1, 0.5)
  double density = 0.0;               ///< ρ [kg/m^3] > 0
  double fracture_toughness = 0.0;    ///< J_c [J/m^2] > 0
  double cohesive_strength = 0.0;     ///< σ_c [Pa] > 0
  double friction_coefficient = 0.0;  ///< μ >= 0 (tool on body)
  double damping = 0.0;               ///< Kelvin–Voigt viscosity η [Pa s] >= 0
};

/// A supported face: `bonded` fixes all displacement (paper 001's samples were glued to a
/// plate); `sliding` fixes the normal displacement only (a block resting on a table).
struct Support {
  enum class Kind { bonded, sliding };
  std::string surface; ///< physical surface name
  Kind kind = Kind::bonded;
};

/// A tool: a blade, or a sphere/stylus tip of radius `radius`, and its trajectory.
struct Tool {
  enum class Kind { blade, sphere };
  std::string name;
  Kind kind = Kind::blade;
  BladeShape blade;           ///< blade only (meshes/blade_shape.hpp)
  double radius = 0.0;        ///< [m] > 0, sphere only
  /// Sphere only: the stylus grasps the surface (paper 000 §2.1: "pulling up"; §2.2: tearing) over
  /// the disc of this radius [m] > 0 centred under its tip at its start. The disc is a physical region
  /// of the geometry (its mesh conforms to the rim), the same for the reference and every model
  /// that grasps, whatever the mesh. Absent: the stylus presses (contact), it does not grasp.
  std::optional<double> grasp_radius;
  /// Sphere with a grasp_radius only: the disc is held by a compliant adhesive layer, an elastic
  /// foundation of this stiffness per unit area k [N/m^3] > 0 between the disc and the tool
  /// (traction on the body t = k (d − u), d the tool's displacement since contact; docs/scenes.md
  /// "Grasp"). Absent: the disc moves rigidly with the tool (tied).
  std::optional<double> grasp_stiffness;
  TrajectorySpec trajectory;
};

/// Paper 002 Table 1 parameters of the local voxel/polygon cutting model, as written there.
struct VoxelModelSettings {
  double elastic_coefficient = 0.0;     ///< [N/m^2] (Table 1 unit)
  double friction_coefficient = 0.0;
  double damping_coefficient = 0.0;     ///< [N s/m^2]
  double critical_force_cutting = 0.0;  ///< [N]
  double critical_force_depth = 0.0;    ///< [N]
  double advance_length = 0.0;          ///< [m]
  std::array<int, 3> grid{10, 20, 20};  ///< local voxel grid cells (paper 002 §4: 10x20x20)
  bool depth_cutting_stiffness = true;  ///< DCS of paper 002 §2.4 on (Figs. 6-7 cases c, d) or off (a)
  bool clip_friction = true;            ///< CFF of paper 002 Eq. (1) on (case d) or off (a, c)
};

/// Calibrated setting of the spring-network model (paper 000 §2), [models.springs]; written by
/// `kerf calibrate` (docs/studies.md).
struct SpringsModelSettings {
  /// Factor on the Young's modulus the network's spring constants are identified from (paper 000
  /// §2.1 identifies them from E and ν of the continuum; a coarse network around the stylus is
  /// stiffer or softer than the body it stands for, and calibration fits this factor) [–] > 0.
  double stiffness_scale = 1.0;
  // The network's own settings (docs/scenes.md, [models.springs]); absent ones take the model's
  // defaults or the material's values.
  std::optional<int> cells;              ///< N: cells per side of the block around the styluses (>= 1; default 8)
  std::optional<double> cell_size;       ///< h [m] > 0; absent or "auto": the block side over N
  std::optional<std::string> integrator; ///< "explicit", "implicit" or "static" (default explicit; --integrator overrides)
  std::optional<bool> volume_term;       ///< per-cell volume term (default on; represents ν >= 1/4)
  std::optional<double> tensile_limit;   ///< tearing stress limit σ_max [Pa] > 0 (default: material cohesive_strength)
  std::optional<double> damping;         ///< Kelvin–Voigt viscosity η [Pa s] >= 0 (default: material damping)
  std::optional<double> grasp_radius;    ///< nodes within it of a stylus tip centre are attached [m] > 0 (default r + h/2)
};

struct Scene {
  std::filesystem::path file;        ///< the scene file as given
  std::string name;
  std::string description;
  PhenomenonSet phenomena;
  SceneGeometry geometry;
  Material material;                 ///< base material (region "body")
  std::vector<Material> layers;      ///< per-region overrides, complete materials
  std::vector<Support> supports;
  std::vector<Tool> tools;           ///< one or two
  std::optional<FractureResponseParameters> fracture;  ///< [models.fracture]
  std::optional<VoxelModelSettings> voxel;             ///< [models.voxel]
  std::optional<SpringsModelSettings> springs;         ///< [models.springs]
};

} // namespace kerf
