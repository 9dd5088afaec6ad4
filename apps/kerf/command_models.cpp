// kerf models: the models and the phenomena each covers.

#include "apps/kerf/commands.hpp"
#include "experiments/models/model_catalogue.hpp"

#include <cstdio>

namespace kerf::cli {

void add_models_command(CLI::App& app) {
  auto* models = app.add_subcommand("models", "list the models and the phenomena each covers");
  models->callback([] {
    for (const ModelDescription& m : model_catalogue()) {
      std::printf("%-10s %s\n", std::string(m.name).c_str(), std::string(m.summary).c_str());
      std::printf("%-10s covers: %s; tools: %s; source: %s\n", "", m.covers.to_string().c_str(),
                  std::string(m.tools).c_str(), std::string(m.source).c_str());
    }
  });
}

} // namespace kerf::cli
