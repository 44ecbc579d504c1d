//! The photomontage studio.

fn main() -> anyhow::Result<()> {
    Ok(())
}
