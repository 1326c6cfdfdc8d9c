# SPDX-License-Identifier: Apache-2.0
"""Wire-coupled arc kinematics of the elastic tail and the Lighthill swimming-speed model."""
