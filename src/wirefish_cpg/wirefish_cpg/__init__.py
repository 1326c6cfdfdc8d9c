# SPDX-License-Identifier: Apache-2.0
"""The fish's Ijspeert CPG (eq 1): the cpg node, its gaits and the gait library it reads."""
