"""The side-by-side benchmarks: report (arithmetic and the table, no ROS), run (the measurements
on a private ROS graph) and pybullet_loop (bare pybullet, the reference of the Bullet node)."""
