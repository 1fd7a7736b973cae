"""A seeded corpus of broken and hostile input files, and the sweep that loads them."""
