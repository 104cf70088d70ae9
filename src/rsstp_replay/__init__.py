"""RSSTP replay: read recordings, reconstruct memory and model, audit, export, view."""
