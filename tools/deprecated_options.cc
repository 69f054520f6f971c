#include "tools/deprecated_options.h"

#include <set>

namespace aerocal::tools {

const std::vector<DeprecatedOption>& DeprecatedOptions() {
  static const std::vector<DeprecatedOption> table = {
      {"camera convert", "--pixel-mm", "--pixel-size-mm", "0.2.0"},
      {"camera show", "--pixel-mm", "--pixel-size-mm", "0.2.0"},
      {"quality mtf", "--pixel-mm", "--pixel-size-mm", "0.2.0"},
      {"quality bars", "--pixel-mm", "--pixel-size-mm", "0.2.0"},
      {"quality star", "--pixel-mm", "--pixel-size-mm", "0.2.0"},
      {"match", "--sigma", "--sigma-px", "0.2.0"},
      {"stitch", "--sigma", "--sigma-px", "0.2.0"},
      {"pushbroom control", "--out-dir", "--out", "0.2.0"},
      {"import colmap", "--model", "--colmap-model", "0.2.0"},
      {"simulate", "--images", "--render-images", "0.2.0"},
      {"simulate", "--points", "--surveyed-points", "0.2.0"},
  };
  return table;
}

namespace {

bool IsOption(const std::string& token) { return token.size() > 1 && token[0] == '-'; }

// The command words of `args`: global flags (they take no value) skipped, then the words up to
// the first option. "aerocal --quiet camera convert --from x IN OUT" gives {"camera", "convert"}
// and the index of "--from".
std::vector<std::string> CommandWords(const std::vector<std::string>& args, size_t& first_option) {
  std::vector<std::string> words;
  size_t i = 1;
  while (i < args.size() && IsOption(args[i])) ++i;
  for (; i < args.size() && !IsOption(args[i]); ++i) words.push_back(args[i]);
  first_option = i;
  return words;
}

bool Names(const std::vector<std::string>& words, const std::string& command) {
  std::string path;
  for (const std::string& word : words) {
    path += path.empty() ? word : " " + word;
    if (path == command) return true;
  }
  return false;
}

}  // namespace

std::vector<std::string> RewriteDeprecatedOptions(std::vector<std::string>& args) {
  size_t first_option = 0;
  const std::vector<std::string> words = CommandWords(args, first_option);
  std::vector<std::string> warnings;
  std::set<std::string> warned;
  for (const DeprecatedOption& d : DeprecatedOptions()) {
    if (!Names(words, d.command)) continue;
    for (size_t i = first_option; i < args.size(); ++i) {
      std::string& token = args[i];
      if (token == "--") break;  // what follows is positional
      const bool bare = token == d.old_name;
      if (!bare && token.rfind(d.old_name + "=", 0) != 0) continue;
      token = d.new_name + token.substr(d.old_name.size());
      if (warned.insert(d.old_name).second)
        warnings.push_back(d.command + " " + d.old_name + " is deprecated and goes in release " +
                           d.removed_in + ": use " + d.new_name);
    }
  }
  return warnings;
}

}  // namespace aerocal::tools
