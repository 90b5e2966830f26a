//! 3-D inverse geometry (being written).
