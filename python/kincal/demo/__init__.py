"""`kincal demo`: the whole pipeline on the built-in examples (pipeline.py), with its accuracy section
(accuracy.py); run and summary_text are this package's."""

from .pipeline import run, summary_text

__all__ = ["run", "summary_text"]
