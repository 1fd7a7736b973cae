"""The maze navigation task (paper Sec. IV-B): batched episodes, fitness and replays."""
