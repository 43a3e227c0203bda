"""Colours shared by the 3-D view and the panels, so a colour means the same thing everywhere."""

ORIGINAL_COLOR = "#1f5fbf"      # original markers: blue
SYNTH_COLOR = "#e8590c"         # synthesized markers (the chosen smoothing): orange
SPLINE_COLOR = "#b33c00"        # synthesized, spline smoothing: dark orange
TRIANGULAR_COLOR = "#f7b27a"    # synthesized, triangular smoothing: light orange
SPEECH_DOT_COLOR = "#222222"    # speech/silence dots
CURSOR_COLOR = "#d6336c"        # the play cursor
LOOP_COLOR = "#2b8a3e"          # the loop range
SURFACE_COLOR = "#ecc9ae"       # the face surface
BACKGROUND = "#ffffff"
