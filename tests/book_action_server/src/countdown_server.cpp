// The action server "countdown" (one feedback per step, the steps and a tally as its result) and
// the service "square", as the book's example_action_server serves its action.
#include <actionlib/server/simple_action_server.h>
#include <book_action_server/CountdownAction.h>
#include <book_action_server/Square.h>
#include <book_action_server/countdown_steps.h>
#include <ros/ros.h>

namespace {

class CountdownServer {
 public:
  explicit CountdownServer(ros::NodeHandle& nh)
      : server_(nh, "countdown", boost::bind(&CountdownServer::execute, this, boost::placeholders::_1),
                false) {
    server_.start();
  }

 private:
  void execute(const book_action_server::CountdownGoalConstPtr& goal) {
    ++tally_.goals_received;
    book_action_server::CountdownResult result;
    for (int remaining : book_action_server::countdownSteps(goal->start)) {
      book_action_server::CountdownFeedback feedback;
      feedback.remaining = remaining;
      server_.publishFeedback(feedback);
      ++tally_.feedback_sent;
      ++result.steps;
    }
    result.tally = tally_;
    server_.setSucceeded(result);
  }

  actionlib::SimpleActionServer<book_action_server::CountdownAction> server_;
  book_action_server::Tally tally_;
};

bool square(book_action_server::Square::Request& request,
            book_action_server::Square::Response& response) {
  response.squared = request.x * request.x;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "countdown_server");
  ros::NodeHandle nh;
  CountdownServer server(nh);
  ros::ServiceServer square_service = nh.advertiseService("square", square);
  ros::spin();
  return 0;
}
