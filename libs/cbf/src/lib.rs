//! Control barrier functions and the three safety filters.
