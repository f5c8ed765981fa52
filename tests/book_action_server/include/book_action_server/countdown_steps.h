#ifndef BOOK_ACTION_SERVER_COUNTDOWN_STEPS_H
#define BOOK_ACTION_SERVER_COUNTDOWN_STEPS_H

#include <vector>

namespace book_action_server {

// The values a countdown from `start` passes through after it starts: start-1, ..., 0 (none
// for a start of zero or less).
std::vector<int> countdownSteps(int start);

}  // namespace book_action_server

#endif
