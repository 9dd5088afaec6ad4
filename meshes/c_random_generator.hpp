#pragma once
// The C library's one random number generator (rand, srand), shared by the libraries kerf calls.
//
// gmsh reseeds it with Mesh.RandomSeed before every mesh and draws from it in its Delaunay
// mesher; METIS, one of the fill-reducing orderings CHOLMOD's analysis tries, reseeds it and
// draws from it too. Each
// alone is deterministic, but in one process with several threads (a study solving two references
// at once, or meshing a scene while a model's network is ordered) one library's srand or rand
// lands in the middle of the other's sequence, and the same scene then meshes differently (one
// node more or less, forces changed by ~1e-4) depending on what ran beside it. Every kerf call
// into such a library holds this lock.

#include <mutex>

namespace kerf {

/// The lock of the C library's random number generator: held around every use of gmsh
/// (meshes/gmsh_io.cpp, where it also serialises gmsh's one global model) and CHOLMOD's analysis
/// with METIS among its orderings (reference/sparse_direct.cpp; the spring network orders with
/// AMD or its own, no METIS).
std::mutex& c_random_generator_mutex();

} // namespace kerf
