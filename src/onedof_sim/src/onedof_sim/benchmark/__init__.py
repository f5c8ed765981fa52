"""The side-by-side benchmarks (rosrun onedof_sim benchmark): cli (the command, the sizes, the
order of the items), one module per measured item (startup, loop_speed, memory, scaling,
round_trips, controller_periods, real_time_factor, lockstep_speed, busy_machine, camera_cost,
laser_cost, window_cost, ...), graph (the private ROS graph, the nodes and bare loops they start,
what a run records), profiling, plots, report (arithmetic and the table, no ROS), pybullet_loop
(bare pybullet, the reference of the Bullet node), concurrent_clients (many clients spawning at
once) and blocking_requests (how long each heavy request holds up another client's
get_world_properties)."""
