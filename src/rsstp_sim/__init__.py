"""RSSTP simulator: a 2D multi-joint arm, its internal model, memory and strategies."""
