// Comma-separated lists of command-line options (--base III,IV).
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace aerocal::tools {

/// The non-empty items of a comma-separated list ("III,IV" -> {"III", "IV"}).
inline std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace aerocal::tools
