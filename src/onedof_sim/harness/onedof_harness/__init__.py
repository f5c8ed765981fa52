"""What the tests and the benchmark run around the simulator, apart from the product package
onedof_sim: private_ros (a private roscore and the processes started against it; the tutorial
player runs on one too), busy (CPU-bound processes beside a run) and book_client (the
book-shaped C++ client's overlay build)."""
