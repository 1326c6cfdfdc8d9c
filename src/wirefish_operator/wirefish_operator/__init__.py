# SPDX-License-Identifier: Apache-2.0
"""The operator's verbs: drive, missions, retune, the gait library, topics and parameters."""
