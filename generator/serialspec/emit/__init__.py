"""Emitters: one module per output, each turning the model into files under generated/."""
