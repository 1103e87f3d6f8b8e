"""Inverse methods: forward operator, KNN population search, Kalman filter, strategy."""
