// Old spellings of options, kept for one release as deprecated aliases (issue 33 item 4: one
// command-line vocabulary). The rewrite runs on argv before CLI11 parses it, so an alias takes
// exactly the new option's checks and help; each use gives a warning naming the new spelling.
#pragma once

#include <string>
#include <vector>

namespace aerocal::tools {

struct DeprecatedOption {
  std::string command;     // "stitch" or "camera convert": the (sub)command it belongs to
  std::string old_name;    // "--sigma"
  std::string new_name;    // "--sigma-px"
  std::string removed_in;  // the release without the alias
};

/// Every deprecated spelling (listed by `aerocal options --markdown` and in docs/options.md).
const std::vector<DeprecatedOption>& DeprecatedOptions();

/// Replaces deprecated spellings in `args` (argv, program name first) for the command they name,
/// "--old" and "--old=VALUE" alike, and returns one warning per replaced option.
std::vector<std::string> RewriteDeprecatedOptions(std::vector<std::string>& args);

}  // namespace aerocal::tools
