"""Follower motion: displacement laws and the motion program built from them."""
