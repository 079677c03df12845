//! Interface control document: fixed-size messages of the partition.
