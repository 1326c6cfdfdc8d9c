"""Pieces the wirefish nodes share: the ROS parameter table."""
