"""gazebo_ros as this workspace provides it: onedof_sim standing in for Gazebo."""
