"""The tutorial: what it plays (phases), its closed-form physics and predictions (physics), and the
headless player of the main job (player), with the pieces it plays with: recorders, runs, summary
and rviz_view."""
