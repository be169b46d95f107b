use byteorder::{LittleEndian, ReadBytesExt};
use std::rc::Rc;

use crate::chunks::DataChunk;
use crate::reader::ArchiveReader;
use crate::result::*;

const ACYCLIC_NUM_SAMPLES: u32 = u32::MAX;
const ACYCLIC_TIME_PER_CYCLE: f64 = f64::MAX / 32.0;
#[derive(Debug)]
pub struct TimeSamplingType {
    pub num_samples_per_cycle: u32,
    pub time_per_cycle: f64,
}
#[derive(Debug)]
pub struct TimeSampling {
    pub sampling_type: TimeSamplingType,
    pub samples: Vec<f64>,
}

pub(crate) fn read_time_samplings_and_max(
    data: &DataChunk,
    reader: &mut dyn ArchiveReader,
) -> Result<(Vec<Rc<TimeSampling>>, Vec<i64>)> {
    let mut buffer = vec![0u8; data.size as usize];
    data.read(0, reader, &mut buffer)?;
    let mut buffer = std::io::Cursor::new(buffer);

    let mut out_max_samples = vec![];
    let mut out_time_samples = vec![];

    loop {
        if buffer.position() == data.size {
            break;
        }

        let max_sample = buffer.read_u32::<LittleEndian>()?;
        out_max_samples.push(max_sample as i64);
        let time_per_cycle = buffer.read_f64::<LittleEndian>()?;
        let num_samples_per_cycle = buffer.read_u32::<LittleEndian>()?;

        // strandlight patch: a corrupt count must not allocate before the read fails.
        let left = (buffer.get_ref().len() as u64).saturating_sub(buffer.position());
        if num_samples_per_cycle as u64 * 8 > left {
            return Err(ParsingError::InvalidAlembicFile.into());
        }
        let mut samples = vec![0.0f64; num_samples_per_cycle as usize];
        buffer
            .read_f64_into::<LittleEndian>(&mut samples)
            .map_err(|_| ParsingError::InvalidAlembicFile)?;

        let sampling_type = if time_per_cycle == f64::MAX / 32.0 {
            TimeSamplingType {
                num_samples_per_cycle: ACYCLIC_NUM_SAMPLES,
                time_per_cycle: ACYCLIC_TIME_PER_CYCLE,
            }
        } else {
            TimeSamplingType {
                num_samples_per_cycle,
                time_per_cycle,
            }
        };

        out_time_samples.push(Rc::new(TimeSampling {
            sampling_type,
            samples,
        }));
    }

    Ok((out_time_samples, out_max_samples))
}
