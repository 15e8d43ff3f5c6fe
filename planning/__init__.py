"""planning: firefly waypoint search, septic smoothing spline and the planner pipeline."""
