// The options every command shares: the backend they ask for and the input script they name.
#include "commands.h"

namespace tender {

BackendOptions CommonOptions::backendOptions() const {
  BackendOptions b = backendOptionsFor(backend, params);
  b.device = device;
  b.validation = validation;
  b.time_kernels = kernel_times;
  return b;
}

std::optional<InputScript> scriptFor(const std::string& path, const SimParams& params, const std::string& backend,
                                     std::string& error) {
  if (path.empty()) return InputScript{};
  return loadScriptFor(path, params, backend, error);
}

} // namespace tender
