"""The tutorial: its closed-form physics (physics) and the headless player of the main job
(player)."""
