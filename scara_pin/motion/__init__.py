"""Motion: joint and straight tool-line paths, time laws, TOPP-RA timing, setpoints, jogging."""
