// Checks that every key a program writes into its JSON outputs is documented: named as `key` in
// configs/README.md (run outputs) or docs/config.md (the sections in more detail). A new key
// without a line of documentation fails the end-to-end tests.
#ifndef RATSLAM_TESTS_DOCUMENTED_KEYS_H_
#define RATSLAM_TESTS_DOCUMENTED_KEYS_H_

#include <cctype>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "tests/test_paths.h"

namespace ratslam::e2e {

// The keys of `j` (of nested objects and of objects in arrays too) that neither page names in
// backquotes. Keys that are numbers ("2", "5": distances) are values, not names.
inline std::set<std::string> UndocumentedKeys(const nlohmann::json& j) {
  static const std::string doc = [] {
    std::stringstream s;
    for (const char* page : {"/configs/README.md", "/docs/config.md"}) {
      std::ifstream in(std::string(ratslam::test_paths::SourceDir()) + page);
      s << in.rdbuf();
    }
    return s.str();
  }();
  std::set<std::string> missing;
  auto walk = [&](const nlohmann::json& node, auto&& self) -> void {
    if (node.is_array()) {
      for (const nlohmann::json& item : node) self(item, self);
    } else if (node.is_object()) {
      for (const auto& [key, value] : node.items()) {
        const bool number = !key.empty() && (std::isdigit(static_cast<unsigned char>(key[0])));
        if (!number && doc.find("`" + key + "`") == std::string::npos) missing.insert(key);
        self(value, self);
      }
    }
  };
  walk(j, walk);
  return missing;
}

inline std::string Join(const std::set<std::string>& keys) {
  std::string s;
  for (const std::string& k : keys) s += (s.empty() ? "" : ", ") + k;
  return s;
}

}  // namespace ratslam::e2e

#endif  // RATSLAM_TESTS_DOCUMENTED_KEYS_H_
