"""Compact result tables of past runs (docs/results/README.md).

Written once from raw run files, read by the commands that regenerate the docs' tables and figures.
"""
