"""Pieces every wirefish node shares: parameter table, main() idiom, signals, QoS, servo joints."""
