#include "calib/core/json_file.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"

#include <algorithm>
#include <memory>
#include <set>
#include <vector>

namespace aerocal {

namespace {

// A parser callback that throws InputError("PATH: a / b: key \"k\" occurs twice in one object")
// at the second occurrence of a key in one object: nlohmann keeps the last, and no reader may
// choose between two values silently (issue 37 class 4). The path names the enclosing keys.
nlohmann::json::parser_callback_t DuplicateKeyCheck(const std::string& path) {
  struct Object {
    std::set<std::string> keys;
    std::string key;  // the key being read (names the objects below it)
  };
  auto objects = std::make_shared<std::vector<Object>>();
  using Event = nlohmann::json::parse_event_t;
  return [objects, path](int, Event event, nlohmann::json& parsed) {
    if (event == Event::object_start) objects->emplace_back();
    if (event == Event::object_end && !objects->empty()) objects->pop_back();
    if (event != Event::key || objects->empty()) return true;
    const std::string key = parsed.get<std::string>();
    if (!objects->back().keys.insert(key).second) {
      std::string where;
      for (size_t i = 0; i + 1 < objects->size(); ++i)
        where += (i ? " / " : "") + (*objects)[i].key;
      throw InputError(path + ": " + (where.empty() ? "" : where + ": ") + "key \"" + key +
                       "\" occurs twice in one object");
    }
    objects->back().key = key;
    return true;
  };
}

}  // namespace

int LineOfOffset(const std::string& text, size_t offset) {
  const auto end = text.begin() + static_cast<std::ptrdiff_t>(std::min(offset, text.size()));
  return 1 + static_cast<int>(std::count(text.begin(), end, '\n'));
}

nlohmann::json ParseJsonText(const std::string& text, const std::string& path) {
  try {
    return nlohmann::json::parse(text, DuplicateKeyCheck(path));
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is 1-based and points just past the offending character.
    const size_t at = e.byte > 0 ? e.byte - 1 : 0;
    std::string reason = e.what();
    const size_t colon = reason.find(": ", reason.find("parse error"));
    if (colon != std::string::npos) reason = reason.substr(colon + 2);
    ThrowInputError({path, LineOfOffset(text, at)}, "invalid JSON (" + reason + ")");
  } catch (const nlohmann::json::exception& e) {
    // Thrown while parsing, without a position: a number beyond the double range (1e999).
    ThrowInputError({path, 0}, std::string("invalid JSON (") + e.what() + ")");
  }
}

nlohmann::json ReadJsonFile(const std::string& path) {
  return ParseJsonText(ReadTextFile(path), path);
}

}  // namespace aerocal
