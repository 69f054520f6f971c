// aerocal validate: result documents checked against their schemas (docs/schema/<kind>.schema.json,
// calib/core/result_file.h ValidateResult): the kind, the schema_version and every key, type and
// bound. For programs that read results (the Python renderers' tests check their inputs with it)
// and for people who keep results.
#include "calib/core/json_file.h"
#include "calib/core/result_file.h"
#include "tools/command_registry.h"

#include <cstdio>
#include <memory>

namespace aerocal::tools {
namespace {

struct ValidateArgs {
  std::vector<std::string> files;
};

CommandRun SetupValidate(CLI::App& app) {
  auto args = std::make_shared<ValidateArgs>();
  app.add_option("files", args->files, "Result documents (JSON) written by aerocal")->required();
  return [args] {
    // Every file is checked before any verdict is printed: the first invalid one is exit 2.
    for (const std::string& file : args->files)
      ValidateResult(ReadJsonFile(file), file, AEROCAL_SCHEMA_DIR);
    for (const std::string& file : args->files) std::printf("%s: valid\n", file.c_str());
    return kExitOk;
  };
}

AEROCAL_REGISTER_COMMAND(validate,
                         "validate",
                         "Check result documents against their schemas (docs/schema)",
                         SetupValidate);

}  // namespace
}  // namespace aerocal::tools
