"""TCP Pendant: a teach-pendant style web app for tool calibration training."""
