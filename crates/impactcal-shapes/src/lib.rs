//! Impact shapes (work in progress in this commit).
