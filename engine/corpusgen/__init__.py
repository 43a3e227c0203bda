"""Synthetic audio-visual corpus (VocalTractLab + a face rig)."""
