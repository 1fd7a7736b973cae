"""The paper's studies: grids of settings x seeds of ordinary evorbc runs, and their reports."""
