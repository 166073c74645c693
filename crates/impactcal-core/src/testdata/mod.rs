//! Measured test data in: CSV records on their own time base ([`TestRecord`]), ISO-MME data
//! sets ([`IsoMme`], ISO/TS 13499) and channel maps tying test channels to model channels
//! ([`ChannelMap`]).

mod channel_map;
mod csv_record;
pub mod isomme;

pub use channel_map::{ChannelMap, MapEntry};
pub use csv_record::TestRecord;
pub use isomme::{IsoMme, IsoMmeChannel, TextEncoding};
