#include <book_action_server/countdown_steps.h>

namespace book_action_server {

std::vector<int> countdownSteps(int start) {
  std::vector<int> steps;
  for (int value = start - 1; value >= 0; --value) steps.push_back(value);
  return steps;
}

}  // namespace book_action_server
