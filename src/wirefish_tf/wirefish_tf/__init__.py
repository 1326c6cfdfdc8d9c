# SPDX-License-Identifier: Apache-2.0
"""The fish's TF tree (REP-105): odom, base_link, imu_link, tail_base and the tail's frames."""
