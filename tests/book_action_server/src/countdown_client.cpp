// Sends one countdown goal from the first argument, calls "square" with the second, and prints
// what came back as lines `key value...`; exits 1 when the goal does not succeed or the call
// fails. It waits for the server as long as it takes: whoever runs it bounds the wait.
#include <actionlib/client/simple_action_client.h>
#include <book_action_server/CountdownAction.h>
#include <book_action_server/Square.h>
#include <ros/ros.h>

#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  ros::init(argc, argv, "countdown_client");
  if (argc < 3) {
    std::fprintf(stderr, "usage: countdown_client START X\n");
    return 2;
  }
  ros::NodeHandle nh;
  actionlib::SimpleActionClient<book_action_server::CountdownAction> client("countdown", true);
  client.waitForServer();

  book_action_server::CountdownGoal goal;
  goal.start = std::atoi(argv[1]);
  client.sendGoal(goal);
  client.waitForResult();
  const actionlib::SimpleClientGoalState state = client.getState();
  std::printf("state %s\n", state.toString().c_str());
  if (state != actionlib::SimpleClientGoalState::SUCCEEDED) return 1;
  const book_action_server::CountdownResultConstPtr result = client.getResult();
  std::printf("steps %d\n", result->steps);
  std::printf("tally %d %d\n", result->tally.goals_received, result->tally.feedback_sent);

  ros::service::waitForService("square");
  book_action_server::Square square;
  square.request.x = std::atoll(argv[2]);
  if (!ros::service::call("square", square)) return 1;
  std::printf("squared %lld\n", static_cast<long long>(square.response.squared));
  return 0;
}
