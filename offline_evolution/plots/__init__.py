"""Pictures of repertoires, runs and replays (matplotlib, PNG)."""
