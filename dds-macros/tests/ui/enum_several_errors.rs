use dds_macros::DdsType;

// Every mistake is reported in one compile, not only the first.
#[derive(DdsType)]
#[dds(mutable, bit_bound = 8)]
enum E {
    A,
    #[dds(value = 0)]
    B,
    #[dds(case = 3)]
    D,
    #[dds(value = 300)]
    C,
}

fn main() {}
