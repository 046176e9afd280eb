"""What every target shares: template rendering, text handling, number formatting, request/response pairing.

A target is a sub-package of `serialspec.backends` (python/, markdown/, ...) exporting `EMITTER`; it reads only the
resolved model (`serialspec.lang.model`) and this layer, never the resolver.
"""
