//! Measured test data in: CSV records on their own time base ([`TestRecord`]), ISO-MME data
//! sets ([`IsoMme`], ISO/TS 13499), split-Hopkinson bar records in the Los Alamos layout
//! ([`LanlBarRecord`]), channel maps tying test channels to model channels ([`ChannelMap`])
//! and the conversions of raw channels into SI ([`Conversion`]: bridges, accelerometers,
//! units).

mod channel_map;
pub mod conversion;
mod csv_record;
pub mod isomme;
pub mod lanl_bar;

pub use channel_map::{ChannelMap, MapEntry};
pub use conversion::{Bridge, Conversion, Unit};
pub use csv_record::TestRecord;
pub use isomme::{IsoMme, IsoMmeChannel, TextEncoding};
pub use lanl_bar::LanlBarRecord;
