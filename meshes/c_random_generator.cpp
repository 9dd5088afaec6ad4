#include "meshes/c_random_generator.hpp"

namespace kerf {

std::mutex& c_random_generator_mutex() {
  static std::mutex mutex;
  return mutex;
}

} // namespace kerf
