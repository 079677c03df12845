//! iceoryx2 transport building blocks for the partition.
