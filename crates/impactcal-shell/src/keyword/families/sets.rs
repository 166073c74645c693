//! Node and part sets.

use super::W10;
use crate::error::Result;
use crate::keyword::reader::{Kw, Reader};
use crate::model::{NodeSet, PartSet};

/// The id of a set keyword (after its title card for `_TITLE`) and its members: ids 8 a
/// card, or with `_GENERATE` ranges `BEG, END` four a card (every id from BEG to END).
fn members(kw: &mut Kw<'_>, what: &str) -> Result<(u64, Vec<u64>)> {
    if kw.has("TITLE") {
        kw.take("the title card")?;
    }
    let c = kw.take("the card SID, DA1-DA4, SOLVER")?;
    let id = kw.fields(&c, W10).id(0, "SID")?;
    let mut ids = Vec::new();
    let generate = kw.has("GENERATE");
    while let Some(c) = kw.next() {
        let f = kw.fields(&c, W10);
        if generate {
            for k in 0..4 {
                let (b, e) = (
                    f.opt_id(2 * k, &format!("B{}BEG", k + 1))?,
                    f.opt_id(2 * k + 1, &format!("B{}END", k + 1))?,
                );
                if b == 0 && e == 0 {
                    continue;
                }
                if b == 0 || e < b || e - b > 10_000_000 {
                    return Err(f.err(format!(
                        "range B{0}BEG {b} to B{0}END {e} is not a range of {what} ids",
                        k + 1
                    )));
                }
                ids.extend(b..=e);
            }
        } else {
            for k in 0..8 {
                match f.opt_id(
                    k,
                    &format!(
                        "{}ID{}",
                        what.to_uppercase().chars().next().unwrap_or('X'),
                        k + 1
                    ),
                )? {
                    0 => {}
                    n => ids.push(n),
                }
            }
        }
    }
    Ok((id, ids))
}

/// `*SET_NODE_LIST` (`*SET_NODE`, `_TITLE`, `_GENERATE`).
pub(crate) fn node_set(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let (id, nodes) = members(kw, "node")?;
    r.model.node_sets.push(NodeSet { id, nodes });
    Ok(())
}

/// `*SET_PART_LIST` (`*SET_PART`, `_TITLE`, `_GENERATE`).
pub(crate) fn part_set(r: &mut Reader<'_>, kw: &mut Kw<'_>) -> Result<()> {
    let (id, parts) = members(kw, "part")?;
    r.model.part_sets.push(PartSet { id, parts });
    Ok(())
}
