//! The event ids that the ICD (`sc_icd::events`, in its C header and its Python partner
//! package) publishes are the ones sc-bus uses.

use sc_icd::events;

#[test]
fn c_header_event_ids_are_sc_bus_ids() {
    assert_eq!(events::SAMPLE as usize, sc_bus::pubsub::EVENT_SAMPLE);
    assert_eq!(
        events::NOTIFIER_DEAD as usize,
        sc_bus::pubsub::EVENT_NOTIFIER_DEAD
    );
    assert_eq!(
        events::NOTIFIER_DROPPED as usize,
        sc_bus::pubsub::EVENT_NOTIFIER_DROPPED
    );
    assert_eq!(events::ID_MAX as usize, sc_bus::pubsub::EVENT_ID_MAX);
    assert_eq!(events::GO as usize, sc_bus::handshake::EVENT_GO);
    assert_eq!(
        events::HANDSHAKE_ID_OFFSET as usize,
        sc_bus::handshake::HANDSHAKE_ID_OFFSET
    );
}
