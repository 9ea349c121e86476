"""Closed-chain mechanisms: four-bar, RSSR, RRSS, RCCC, dyads, finger and thumb linkages."""
