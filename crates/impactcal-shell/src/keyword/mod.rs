//! LS-DYNA keyword decks (placeholder).
