# SPDX-License-Identifier: Apache-2.0
"""The virtual fish: firmware, physics and servos on a pseudo-terminal."""
