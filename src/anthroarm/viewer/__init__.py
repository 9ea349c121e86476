"""meshcat browser viewer."""
