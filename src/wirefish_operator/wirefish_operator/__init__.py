"""The operator's verbs: drive, missions, retune, the gait library, topics and parameters."""
