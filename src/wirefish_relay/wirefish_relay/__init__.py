"""The fish's side of the radio link: the decimated copies the shore sees."""
