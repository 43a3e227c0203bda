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


def fit_ylabel(ax, label: str, max_size: float = 8.0, min_size: float = 5.0) -> None:
    """Set ``ax``'s y label in the largest font, up to ``max_size`` points, whose longest line
    fits the height of the axes (the label runs up the axes: short panels of small windows)."""
    fig = ax.figure
    height_px = ax.get_position().height * fig.get_figheight() * fig.dpi
    longest = max(len(line) for line in label.splitlines())
    size = height_px / (0.62 * longest * fig.dpi / 72.0)
    ax.set_ylabel(label, fontsize=max(min_size, min(max_size, size)))
