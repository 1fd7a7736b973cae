"""Repertoire generation with MAP-Elites (paper Sec. III-A, Algorithm 1)."""
