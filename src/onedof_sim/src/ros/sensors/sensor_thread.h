// The thread the cameras render on: a frame's render, its lens, noise and the image's encoding
// (camera_sensor.h's frame work), and the renderer itself, made there at the first frame so that
// the threads the renderer starts (Mesa's rasterizers on llvmpipe) are made there too and take
// its priority.
//
// One thread for the process, at a lower CPU priority than the rest of the process (a higher
// nice value, which Linux gives a thread of its own): a large render keeps its threads runnable
// for a second or more, and on a busy machine the threads that answer requests (roscpp's network
// thread, the service threads) are then picked before them whenever they have something to do.
// The caller waits for each piece of work, so the work is the loop's own, done in the same order
// on the same data: only the thread that does it differs, and with it how much of a busy
// machine's time it gets. Ray casting is not sent here: it holds the world's lock
// (SensorWork::withWorld), and at a low priority a preempted holder would keep every request
// that waits for the lock waiting longer.
#pragma once

#include <functional>

namespace onedof_sim::plugins {

// Runs work on the sensor thread and returns once it is done; an exception it throws is thrown
// here. Called on the sensor thread itself, it runs work at once.
void onSensorThread(const std::function<void()>& work);

}  // namespace onedof_sim::plugins
