use dds_macros::DdsType;

#[derive(DdsType)]
#[dds(mutable)]
struct Wide {
    #[dds(key, id = 10)]
    id: u32,
    #[dds(id = 7)]
    c: u32,
    d: u32,
    e: u32,
    f: u32,
}

fn main() {}
