"""Arbitrator evolution with NEAT (paper Sec. III-C, IV-D) and the standard-NEAT baseline."""
