// The one whitespace trim of every reader in the workspace (XML text, parameters, lists).
#pragma once

#include <string>
#include <string_view>

namespace onedof_sim {

// `text` without the white space (space, tab, line feed, vertical tab, form feed, carriage
// return) at either end.
inline std::string trimmed(std::string_view text) {
  constexpr std::string_view kSpace = " \t\n\v\f\r";
  const size_t first = text.find_first_not_of(kSpace);
  if (first == std::string_view::npos) return "";
  return std::string(text.substr(first, text.find_last_not_of(kSpace) - first + 1));
}

// The same for a C string; null (an XML element without text) gives "".
inline std::string trimmed(const char* text) {
  return text ? trimmed(std::string_view(text)) : std::string();
}

}  // namespace onedof_sim
