//! Frames, rotations, orbits, Hill frame, Clohessy-Wiltshire and rigid-body attitude models.
