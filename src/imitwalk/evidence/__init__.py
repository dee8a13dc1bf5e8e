"""Evidence of a run: plots, learning curves, film strips and video, and the HTML report."""
