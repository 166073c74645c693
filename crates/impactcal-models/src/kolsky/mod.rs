//! The split-Hopkinson (Kolsky) pressure bar.
//!
//! A striker hits the incident bar; the compressive pulse it launches (the incident wave)
//! runs past a strain gauge to the specimen, squeezed between the incident and the
//! transmitted bar; part of it reflects back past the same gauge as a tensile wave (the
//! reflected wave), part passes through the specimen into the transmitted bar and past its
//! gauge (the transmitted wave). The bars stay elastic, so the three gauge strains give the
//! forces and velocities at both faces of the specimen.
//!
//! Sign convention throughout: compression positive (strains, stresses, forces), particle
//! velocities positive towards the transmitted bar.
