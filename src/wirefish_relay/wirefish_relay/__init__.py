# SPDX-License-Identifier: Apache-2.0
"""The fish's side of the radio link: the decimated copies the shore sees."""
