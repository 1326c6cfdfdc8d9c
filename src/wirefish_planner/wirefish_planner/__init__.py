"""Drive the fish: cmd_vel to gait (inverse speed model) and IMU heading control."""
