// aerocal options (hidden): every option of every command, one per line, tab-separated:
// COMMAND PATH, OPTION NAME, TYPE with the validators' descriptions ("INT:in [1, 10000]").
// Read by the test that walks every numeric option with NaN, infinity, zero, negative and huge
// values (tests/tools/bad_input2_test.cc); not meant for people.
#include <cstdio>
#include <functional>

#include "tools/command_registry.h"

namespace aerocal::tools {
namespace {

void ListOptions(const CLI::App& app, const std::string& path) {
  for (const CLI::Option* option : app.get_options()) {
    if (option->get_lnames().empty() || option->get_lnames().front() == "help") continue;
    // The type name carries the validators' descriptions: "FLOAT:in [0, 10]".
    std::printf("%s\t--%s\t%s\n", path.c_str(), option->get_lnames().front().c_str(),
                option->get_type_name().c_str());
  }
  for (const CLI::App* sub : app.get_subcommands({}))
    if (sub->get_name() != "options") ListOptions(*sub, path.empty() ? sub->get_name() : path + " " + sub->get_name());
}

CommandRun SetupOptions(CLI::App& app) {
  app.group("");  // hidden from --help
  CLI::App* self = &app;
  return [self]() {
    const CLI::App* root = self;
    while (root->get_parent()) root = root->get_parent();
    for (const CLI::App* sub : root->get_subcommands({}))
      if (sub->get_name() != "options") ListOptions(*sub, sub->get_name());
    return kExitOk;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(options, "options", "Lists every option (for the tests)", SetupOptions);

}  // namespace aerocal::tools
