# SPDX-License-Identifier: Apache-2.0
"""The live view of the fish: a Foxglove WebSocket server over the graph and a dashboard."""
