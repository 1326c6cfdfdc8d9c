# SPDX-License-Identifier: Apache-2.0
"""Drive the fish: cmd_vel to gait (inverse speed model) and IMU heading control."""
