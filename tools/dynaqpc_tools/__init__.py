# SPDX-License-Identifier: MIT
"""dynaqpc PC tools: bus monitor, pose viewer, Cricket console, experiment runner."""

__version__ = "0.1.0"
