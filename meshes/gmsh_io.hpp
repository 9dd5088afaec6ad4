#pragma once
// gmsh through its C++ API: mesh a parametric .geo or a closed STL surface into tetrahedra, read
// and write .msh 4.1. One reader for both sides of kerf (the reference builds its deal.II
// triangulation from the TetMesh this returns, see ../shared/notes/dealii-on-debian12.md).

#include "meshes/tet_mesh.hpp"

#include <filesystem>
#include <map>
#include <set>
#include <string>

namespace kerf {

/// Meshes the .geo file `geo` with its parameters overridden by `parameters` (name -> value in
/// SI units; each name must be a parameter the .geo declares with `DefineConstant`, as
/// `NAME = {default, Name "Parameters/NAME"}` like every file in meshes/geo, otherwise
/// MeshError listing the declared names) and the target element size `element_size` [m]. Returns first-order tetrahedra with
/// all physical groups of the .geo. Throws MeshError naming the file on any gmsh error.
TetMesh mesh_geo(const std::filesystem::path& geo, const std::map<std::string, double>& parameters,
                 double element_size);

/// Meshes the volume enclosed by a closed STL surface (a scan, say; coordinates in metres after
/// multiplying by `scale`) with element size `element_size` [m]. The result has the physical
/// volume `body` and the physical surface `boundary`.
/// The names of the parameters `geo` declares (its DefineConstant blocks, ONELAB
/// "Parameters/NAME"), read by opening it with its defaults. Throws MeshError if it cannot be read.
std::set<std::string> geo_parameter_names(const std::filesystem::path& geo);

TetMesh mesh_stl(const std::filesystem::path& stl, double element_size, double scale = 1.0);

/// Reads a .msh file (any version gmsh reads) holding first-order tetrahedra and triangles.
/// Tetrahedra keep the node order of the file: an inverted element stays inverted (the quality
/// summary reports it; kerf refuses such a mesh when a scene loads it).
TetMesh read_msh(const std::filesystem::path& msh);

/// Writes .msh 4.1 ASCII with nodes, tetrahedra and physical groups, atomically
/// (temporary file, then rename).
void write_msh(const TetMesh& mesh, const std::filesystem::path& msh);

} // namespace kerf
