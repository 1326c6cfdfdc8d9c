# SPDX-License-Identifier: Apache-2.0
"""Pieces every wirefish node shares: parameter table, main() idiom, signals, QoS, servo joints."""
