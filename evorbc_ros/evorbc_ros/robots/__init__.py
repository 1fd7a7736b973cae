"""Robot definitions shared by the onboard executor and the simulator."""
