// The one reading of a number written as text, for every reader in the workspace (XML text,
// parameters): whether the whole text is one number, as strtod reads it.
#pragma once

#include <cmath>
#include <cstdlib>
#include <string>

namespace onedof_sim {

// True, with *value set, when `text` is one number and nothing else (no white space around it:
// trim first), infinities included, NaN not; false for an empty text. A caller that wants a finite
// number checks std::isfinite.
inline bool numberIn(const std::string& text, double* value) {
  char* end = nullptr;
  const double parsed = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || std::isnan(parsed)) return false;
  *value = parsed;
  return true;
}

}  // namespace onedof_sim
