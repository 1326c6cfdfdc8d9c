# SPDX-License-Identifier: Apache-2.0
"""Rosbag2 (MCAP) recording, recovery, replay and reports: the recorder and the bag verbs."""
