"""The tutorial: what it plays (phases), its closed-form physics and predictions (physics), and the
headless player of the main job (player), with the pieces it plays with: recorders, runs, summary,
rviz_view, and gazebo_window (the simulator's window driven with the mouse, for --gui-table)."""
