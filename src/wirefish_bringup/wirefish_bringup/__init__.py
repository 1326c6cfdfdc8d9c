"""Launch files, default parameters and the wirefish command-line tool."""
