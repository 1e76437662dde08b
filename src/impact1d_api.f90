!> Flat interface for f2py (and a future C API): scalars, explicit-shape arrays, a status
!> code and a message; derived types stay inside. Status 0 ok, 1 input error, 2 simulation
!> error, 3 the caller's arrays were too small (see simulate). No state is kept between calls:
!> everything a run produced comes back from the call that ran it, so threads may run scenes
!> at once (the long calls are `threadsafe` for f2py: they release the GIL). A prepared scene
!> (prepare) is what that call returns: the caller owns it by its handle and frees it.
module impact1d_api
  use, intrinsic :: iso_c_binding, only: c_double, c_int, c_intptr_t
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, status_ok, status_input, status_interrupted, raise, fmt
  use impact1d_interrupt, only: catch_interrupts, interrupt_count
  use impact1d_scene, only: scene_input, scene_type, validate, n_real, n_text, real_names, text_names, &
    i_title, i_f1_table, i_f2_table, i_method, i_substeps, i_events, set_text, i_x_left_table, i_x_right_table
  use impact1d_io, only: read_scene_file, prepare_scene
  use impact1d_chain, only: settle_chain, validate_chain, n_ids, id_arrays, id_r_meet, field_name, assign_number, &
    assign_text, scene_assignments
  use impact1d_fields, only: text_item, a_f_table
  use impact1d_output, only: memory_sink, summary_sink, column_names_text => column_names, event_names, &
    n_columns, event_impact, event_rest, present_columns, class_impact, impacts_on, &
    row_length, row_ledger, final_row, check_bodies_out
  use impact1d_solver, only: run, run_stats
  use impact1d_prepared, only: prepared_scene, prepared_handle, prepared_entry, prepared_free
  implicit none
  private
  public :: field_names, column_names, event_kind_names, read_scene, simulate, simulate_summaries, &
    summary_column_names, input_field_names, settle_scene, interrupt_epoch_now, prepare, run_prepared, &
    release_prepared

  integer(c_int), parameter :: status_too_small = 3   !< arrays too small: sizes needed returned
  !> Room for a message: whole for any message the core builds from the paths and texts it
  !> was given, up to three paths of the system's limit (4096 bytes) each. (It was 512: a
  !> long path name cut the message.) A sweep keeps 512 characters per run (its memory is
  !> per run): the caller runs a run whose message fills them again through simulate.
  integer, parameter :: message_length = 16384
  !> What simulate_summaries keeps of a run (sweep's columns, in this order).
  character(len=*), parameter :: summary_names(17) = [character(len=15) :: 'x1_end', 'v1_end', &
    'x2_end', 'v2_end', 'ke_end', 'n_impacts', 'n_left', 'n_right', 'n_slot_min', 'n_slot_max', &
    't_rest', 'impact_loss', 'friction_loss', 'energy_residual', 'steps', 'pe_end', 'damping_loss']

contains

  !> Names of the scene's real and text fields, space separated, in the order of the arrays.
  subroutine field_names(real_field_names, text_field_names)
    character(len=1024), intent(out) :: real_field_names, text_field_names
    real_field_names = joined(real_names)
    text_field_names = joined(text_names)
  end subroutine field_names

  !> Names of the sample columns, space separated.
  subroutine column_names(names)
    character(len=1024), intent(out) :: names
    names = column_names_text
  end subroutine column_names

  !> Event kind names, space separated: code k is the k-th word.
  subroutine event_kind_names(names)
    character(len=1024), intent(out) :: names
    names = joined(event_names)
  end subroutine event_kind_names

  !> Names of every input field, space separated: field id k is the k-th word (the
  !> tutorial's scalars, its texts, the arrays, r_meet, 'contact.a' ..., 'spring.a' ...:
  !> impact1d_chain's numbering).
  subroutine input_field_names(names)
    character(len=2048), intent(out) :: names
    character(len=24) :: words(n_ids)
    integer :: id
    do id = 1, n_ids
      words(id) = field_name(id)
    end do
    names = joined(words)
  end subroutine input_field_names

  !> Read and check a scene file ('.dat': VisSim-style parameters; else a namelist) and give
  !> it back as assignments: number k sets field(k) (input_field_names' numbering) at index(k)
  !> (0 for a scalar, the element of an array, the record of a record field) to value(k);
  !> text k sets text_field(k) at text_index(k) to text_codes(:text_lengths(k), k). A scene
  !> of one or two bodies comes back in the tutorial's scalars. When there are more numbers
  !> or texts than max_numbers, max_texts, or a text longer than text_room, status is 3 and
  !> n_numbers, n_texts, text_lengths say the room needed: call again with it.
  subroutine read_scene(path, max_numbers, max_texts, text_room, field, index, value, text_field, text_index, &
      text_codes, text_lengths, n_numbers, n_texts, status, message)
    !f2py threadsafe
    character(len=*), intent(in) :: path
    integer(c_int), intent(in) :: max_numbers, max_texts, text_room
    integer(c_int), intent(out) :: field(max_numbers), index(max_numbers), text_field(max_texts), &
      text_index(max_texts), text_codes(text_room, max_texts), text_lengths(max_texts)
    real(c_double), intent(out) :: value(max_numbers)
    integer(c_int), intent(out) :: n_numbers, n_texts, status
    character(len=16384), intent(out) :: message    ! 16384: message_length (f2py needs the number)
    type(scene_input) :: input
    type(error_type), allocatable :: error
    type(text_item) :: texts(max_texts)
    integer :: fields(max_numbers), indices(max_numbers), k
    real(wp) :: values(max_numbers)

    field = 0; index = 0; value = 0.0_c_double; text_field = 0; text_index = 0
    text_codes = ichar(' '); text_lengths = 0; n_numbers = 0; n_texts = 0
    call read_scene_file(path, input, error)
    if (failed(error, status, message)) return
    call scene_assignments(input, fields, indices, values, k, text_field, text_index, texts, n_texts)
    n_numbers = k
    k = min(n_numbers, max_numbers)
    field(:k) = fields(:k)
    index(:k) = indices(:k)
    value(:k) = real(values(:k), c_double)
    do k = 1, min(n_texts, max_texts)
      text_lengths(k) = len(texts(k)%s)
      call put_codes(texts(k)%s, text_codes(:, k))
    end do
    if (n_numbers > max_numbers .or. n_texts > max_texts .or. any(text_lengths > text_room)) then
      status = status_too_small
      message = 'internal: the assignment arrays are too small'
    end if
  end subroutine read_scene

  !> A scene given as assignments (read_scene's form; texts as one blob, text k ending at
  !> text_end(k)), checked as a file's is, in the tutorial's flat fields (simulate's): values,
  !> given and the texts (text_codes(:text_lengths(k), k), in field_names' order) of a scene
  !> of one or two bodies (its &contact and &spring records, checked here, are not in them:
  !> simulate takes them as assignments of their own). Arrays of one or two bodies fold
  !> into the tutorial's fields; more than two bodies are an input error (status 1) until
  !> the cluster solver runs them.
  subroutine settle_scene(n_numbers, n_texts, number_room, field, index, value, text_room_in, text_field, &
      text_index, text_end, text_blob, n, text_room, values, given, text_codes, text_lengths, status, message)
    !f2py threadsafe
    ! (the arrays are number_room, text_room_in >= 1 long, the counts given apart: f2py
    ! refuses arrays of no element)
    integer(c_int), intent(in) :: n_numbers, n_texts, number_room, text_room_in, n, text_room
    integer(c_int), intent(in) :: field(number_room), index(number_room), text_field(text_room_in), &
      text_index(text_room_in), text_end(text_room_in)
    real(c_double), intent(in) :: value(number_room)
    character(len=*), intent(in) :: text_blob
    real(c_double), intent(out) :: values(n)
    integer(c_int), intent(out) :: given(n)
    integer(c_int), intent(out) :: text_codes(text_room, 8)    ! 8: n_text (f2py needs the number)
    integer(c_int), intent(out) :: text_lengths(8)
    integer(c_int), intent(out) :: status
    character(len=16384), intent(out) :: message    ! 16384: message_length (f2py needs the number)
    type(scene_input) :: input
    type(error_type), allocatable :: error
    integer :: k

    values = 0.0_c_double
    given = 0
    text_codes = ichar(' ')
    text_lengths = 0
    if (.not. field_count_ok(n, status, message)) return
    do k = 1, n_text
      call set_text(input, k, '')
    end do
    call apply_assignments(input, .false., n_numbers, n_texts, field, index, value, text_field, text_index, &
      text_end, text_blob, error)
    if (failed(error, status, message)) return
    call settle_chain(input, error)
    if (.not. allocated(error)) call validate(input, .false., error)
    if (.not. allocated(error)) call validate_chain(input, error)
    if (failed(error, status, message)) return
    values = real(input%value, c_double)
    given = merge(1_c_int, 0_c_int, input%given)
    do k = 1, n_text
      text_lengths(k) = len_trim(input%text(k)%s)
      call put_codes(trim(input%text(k)%s), text_codes(:, k))
    end do
    if (any(text_lengths > text_room)) then
      status = status_too_small
      message = 'internal: the text buffers are too small'
    end if
  end subroutine settle_scene

  !> Check and run a scene given as flat fields (its &contact and &spring records as
  !> assignments beside them: settle_scene's form, record fields only, n_numbers = n_texts
  !> = 0 for none; their texts record_blob, text k ending at record_text_end(k)), into arrays the caller owns and may reuse
  !> (f2py passes intent(inout) arrays through without a copy or a new array: with the
  !> outputs made by f2py, 16 kB of message among them, the call cost ~10 us against ~2 us
  !> of Fortran work for a short run). The texts are text_blob, text k ending at
  !> text_end(k) (field_names' order). The samples fill samples(:n_samples, :), the events
  !> event_real(:n_events, :) = [t, v_a before, v_b before, v_a after, v_b after] and
  !> event_int(:n_events, :) = [class, index, end a, end b] (a column each: what Python
  !> reads, contiguous): class 1 impact, 2 rest, 3
  !> release of row index (named '', 'rest_', 'release_' and the row's name), 4 stick, 5 slip
  !> of body index ('stick', 'slip' and the body's number), reporting the bodies (end a, end
  !> b) (0: none; (1, 2) with two bodies, (1, 0) with one). The run's row names fill
  !> row_name_codes(:, :n_rows) as character codes (blank-padded). has_column(k) is 1 for
  !> the columns of the run's full row (impact1d_output's row_length(N) = 2 max(N, 2) + 9:
  !> t, x1 v1 .. xN vN, ke, pe, work, friction_loss, impact_loss, damping_loss, drive_work,
  !> residual; for one or two bodies column_names) that the scene has (x2 and v2 only with a
  !> second body, x and v only of the bodies of &run bodies_out, pe and damping_loss with
  !> springs and dampers, drive_work with a moving ground): they fill samples' first
  !> columns, in that order; n_cols (samples' and has_column's length) must be row_length(N)
  !> at least. info = [status, n_samples, n_events, n_rows, steps, message length, warnings
  !> length, N] and energy_residual(1)
  !> come back; the message and the warnings (one per line) fill text_codes(:length, 1) and
  !> (:length, 2) as character codes. When any array needs more room than the caller gave,
  !> status is 3 and n_samples, n_events, n_rows, N are the sizes needed: call again with
  !> them (too few columns: nothing was run).
  subroutine simulate(n, values, given, text_blob, text_end, n_numbers, n_texts, number_room, field, index, value, &
      record_text_room, record_text_field, record_text_index, record_text_end, record_blob, progress, max_samples, &
      n_cols, max_events, max_rows, text_room, samples, has_column, event_real, event_int, row_name_codes, info, &
      energy_residual, text_codes, interrupt_epoch)
    !f2py threadsafe
    !f2py integer(c_int) optional, intent(in) :: interrupt_epoch = -1
    integer(c_int), intent(in) :: n, max_samples, n_cols, max_events, max_rows, text_room
    real(c_double), intent(in) :: values(n)
    integer(c_int), intent(in) :: given(n), text_end(8)          ! 8: n_text (f2py needs the number)
    character(len=*), intent(in) :: text_blob
    integer(c_int), intent(in) :: progress    !< non-zero: show progress on stderr after 1 s
    real(c_double), intent(inout), target :: samples(max_samples, n_cols)
    integer(c_int), intent(inout) :: has_column(n_cols), event_int(max_events, 4), info(8)
    real(c_double), intent(inout) :: event_real(max_events, 5), energy_residual(1)
    integer(c_int), intent(inout) :: row_name_codes(32, max_rows)   ! 32: name_len (f2py needs the number)
    integer(c_int), intent(inout) :: text_codes(text_room, 2)
    integer(c_int), intent(in) :: n_numbers, n_texts, number_room, record_text_room
    integer(c_int), intent(in) :: field(number_room), index(number_room), record_text_field(record_text_room), &
      record_text_index(record_text_room), record_text_end(record_text_room)
    real(c_double), intent(in) :: value(number_room)
    character(len=*), intent(in) :: record_blob
    integer(c_int), intent(in) :: interrupt_epoch   !< from interrupt_epoch_now (-1: the count at the run's start)
    type(scene_input) :: input
    type(scene_type) :: scene
    type(error_type), allocatable :: error

    info = 0
    has_column = 0
    energy_residual = 0.0_c_double
    call set_up(n, values, given, text_blob, text_end, n_numbers, n_texts, field, index, value, record_text_field, &
      record_text_index, record_text_end, record_blob, n_cols, input, scene, error)
    if (put_error(error, info, text_codes)) return
    call run_scene(scene, present_columns(input), progress, max_samples, n_cols, max_events, max_rows, text_room, &
      samples, has_column, event_real, event_int, row_name_codes, info, energy_residual, text_codes, interrupt_epoch)
  end subroutine simulate

  !> A scene in simulate's form (n to record_blob, as simulate takes them) validated and
  !> built once, kept for run_prepared: handle (non-zero) names it until release_prepared
  !> frees it (impact1d_prepared: the caller owns it). handle is 0 when the scene fails its
  !> checks or reads a force table (a file, read afresh each run): the caller runs it
  !> through simulate, which says what is wrong.
  subroutine prepare(n, values, given, text_blob, text_end, n_numbers, n_texts, number_room, field, index, value, &
      record_text_room, record_text_field, record_text_index, record_text_end, record_blob, handle)
    !f2py threadsafe
    integer(c_int), intent(in) :: n
    real(c_double), intent(in) :: values(n)
    integer(c_int), intent(in) :: given(n), text_end(8)          ! 8: n_text (f2py needs the number)
    character(len=*), intent(in) :: text_blob
    integer(c_int), intent(in) :: n_numbers, n_texts, number_room, record_text_room
    integer(c_int), intent(in) :: field(number_room), index(number_room), record_text_field(record_text_room), &
      record_text_index(record_text_room), record_text_end(record_text_room)
    real(c_double), intent(in) :: value(number_room)
    character(len=*), intent(in) :: record_blob
    integer(c_intptr_t), intent(out) :: handle
    type(scene_input) :: input
    type(prepared_scene), pointer :: entry
    type(error_type), allocatable :: error

    handle = 0
    allocate(entry)
    call set_up(n, values, given, text_blob, text_end, n_numbers, n_texts, field, index, value, record_text_field, &
      record_text_index, record_text_end, record_blob, n_columns, input, entry%scene, error)
    if (allocated(error) .or. reads_tables(input)) then
      deallocate(entry)
      return
    end if
    entry%columns = present_columns(input)
    handle = prepared_handle(entry)
  end subroutine prepare

  !> Run the scene prepare made (handle): simulate's outputs and statuses, the same
  !> arrays (a handle that names none: status 1, an internal error). interrupt_epoch is
  !> not optional here: Python passes it by position (f2py reads keywords more slowly).
  subroutine run_prepared(handle, progress, max_samples, n_cols, max_events, max_rows, text_room, samples, &
      has_column, event_real, event_int, row_name_codes, info, energy_residual, text_codes, interrupt_epoch)
    !f2py threadsafe
    integer(c_intptr_t), intent(in) :: handle
    integer(c_int), intent(in) :: progress, max_samples, n_cols, max_events, max_rows, text_room
    real(c_double), intent(inout), target :: samples(max_samples, n_cols)
    integer(c_int), intent(inout) :: has_column(n_cols), event_int(max_events, 4), info(8)
    real(c_double), intent(inout) :: event_real(max_events, 5), energy_residual(1)
    integer(c_int), intent(inout) :: row_name_codes(32, max_rows)   ! 32: name_len (f2py needs the number)
    integer(c_int), intent(inout) :: text_codes(text_room, 2)
    integer(c_int), intent(in) :: interrupt_epoch
    type(prepared_scene), pointer :: entry
    type(error_type), allocatable :: error

    info = 0
    has_column = 0
    energy_residual = 0.0_c_double
    entry => prepared_entry(handle)
    if (.not. associated(entry) .or. n_cols < n_columns) &
      call raise(error, status_input, 'internal: no prepared scene of that handle, or too few sample columns')
    if (put_error(error, info, text_codes)) return
    call run_scene(entry%scene, entry%columns, progress, max_samples, n_cols, max_events, max_rows, text_room, &
      samples, has_column, event_real, event_int, row_name_codes, info, energy_residual, text_codes, interrupt_epoch)
  end subroutine run_prepared

  !> Free the scene prepare made (handle, once; 0: nothing), when no run uses it.
  subroutine release_prepared(handle)
    integer(c_intptr_t), intent(in) :: handle
    call prepared_free(handle)
  end subroutine release_prepared

  !> simulate's scene (its arguments n to record_blob) checked and built: input as written,
  !> scene as run. n_cols: the caller's sample columns (too few is an internal error).
  subroutine set_up(n, values, given, text_blob, text_end, n_numbers, n_texts, field, index, value, &
      record_text_field, record_text_index, record_text_end, record_blob, n_cols, input, scene, error)
    integer(c_int), intent(in) :: n, n_cols
    real(c_double), intent(in) :: values(:)
    integer(c_int), intent(in) :: given(:), text_end(:)
    character(len=*), intent(in) :: text_blob
    integer(c_int), intent(in) :: n_numbers, n_texts, field(:), index(:), record_text_field(:), &
      record_text_index(:), record_text_end(:)
    real(c_double), intent(in) :: value(:)
    character(len=*), intent(in) :: record_blob
    type(scene_input), intent(out) :: input
    type(scene_type), intent(out) :: scene
    type(error_type), allocatable, intent(out) :: error
    if (n /= n_real .or. n_cols < n_columns .or. any(text_end < 0 .or. text_end > len(text_blob)) .or. &
        any(text_end(2:) < text_end(:7))) then
      call raise(error, status_input, 'internal: the scene''s fields, texts or sample columns do not match the core')
      return
    end if
    input = flat_input(values, given, text_blob(:text_end(1)), text_blob(text_end(1) + 1:text_end(2)), &
      text_blob(text_end(2) + 1:text_end(3)), text_blob(text_end(3) + 1:text_end(4)), &
      text_blob(text_end(4) + 1:text_end(5)), text_blob(text_end(5) + 1:text_end(6)), &
      text_blob(text_end(6) + 1:text_end(7)), text_blob(text_end(7) + 1:text_end(8)))
    call apply_scene_assignments(input, n_numbers, n_texts, field, index, value, record_text_field, &
      record_text_index, record_text_end, record_blob, error)
    if (.not. allocated(error)) call prepare_scene(input, scene, error)
    if (.not. allocated(error)) call check_bodies_out(input, error)
  end subroutine set_up

  !> Whether the scene names a force table (f1_table, f2_table, f_table(i)): a file that
  !> may change between runs, so its scene is not prepared once for many.
  logical function reads_tables(input)
    type(scene_input), intent(in) :: input
    integer :: i
    reads_tables = len_trim(input%text(i_f1_table)%s) > 0 .or. len_trim(input%text(i_f2_table)%s) > 0
    do i = 1, input%chain%array(a_f_table)%n
      reads_tables = reads_tables .or. len_trim(input%chain%array(a_f_table)%t(i)%s) > 0
    end do
  end function reads_tables

  !> The run of a scene set up (simulate's, or a prepared one) with the present columns,
  !> into the caller's arrays: simulate's outputs from info on (info, has_column and
  !> energy_residual already zero).
  subroutine run_scene(scene, columns, progress, max_samples, n_cols, max_events, max_rows, text_room, samples, &
      has_column, event_real, event_int, row_name_codes, info, energy_residual, text_codes, interrupt_epoch)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: columns(:)
    integer(c_int), intent(in) :: progress, max_samples, n_cols, max_events, max_rows, text_room, interrupt_epoch
    real(c_double), intent(inout), target :: samples(max_samples, n_cols)
    integer(c_int), intent(inout) :: has_column(n_cols), event_int(max_events, 4), info(8)
    real(c_double), intent(inout) :: event_real(max_events, 5), energy_residual(1)
    integer(c_int), intent(inout) :: row_name_codes(32, max_rows)
    integer(c_int), intent(inout) :: text_codes(text_room, 2)
    type(run_stats) :: stats
    type(memory_sink) :: sink
    type(error_type), allocatable :: error
    character(len=:), allocatable :: note, warnings
    integer :: k, n_samples, n_events, n_rows

    warnings = trim(scene%warnings)
    info(8) = scene%n_bodies
    if (n_cols < row_length(scene%n_bodies)) then
      info(1) = status_too_small
      return
    end if
    call catch_interrupts()
    has_column(columns) = 1
    ! The rows go straight into samples when it has room (else the sink keeps them and the
    ! caller learns the size needed).
    if (max_samples >= scene%n_samples) then
      call sink%reserve(scene%n_samples, columns, samples)
    else
      call sink%reserve(scene%n_samples, columns)
    end if
    sink%show_progress = progress /= 0
    sink%events = scene%events
    sink%max_events = scene%max_events
    call run(scene, sink, stats, error, int(interrupt_epoch))
    call sink%end_progress()
    if (put_error(error, info, text_codes)) return
    ! A log cut at max_events says so beside the scene's warnings (Result.warnings).
    call sink%cut_note(note)
    if (len(note) > 0) warnings = warnings // repeat(new_line('a'), min(len(warnings), 1)) // note
    n_samples = sink%n_samples
    n_events = sink%n_events
    n_rows = scene%n_rows + scene%n_stops
    info(2:5) = [n_samples, n_events, n_rows, int(min(stats%steps, int(huge(1_c_int), kind(stats%steps))), c_int)]
    energy_residual = stats%max_residual
    if (n_samples > max_samples .or. n_events > max_events .or. n_rows > max_rows .or. len(warnings) > text_room) then
      info(1) = status_too_small
      return
    end if
    info(7) = len(warnings)
    call put_codes(warnings, text_codes(:len(warnings), 2))
    ! The present columns first, in order (has_column says which they are): already there.
    event_real(:n_events, 1) = sink%event_time(:n_events)
    event_real(:n_events, 2:5) = transpose(sink%event_v(:, :n_events))
    event_int(:n_events, 1) = sink%event_class(:n_events)
    event_int(:n_events, 2) = sink%event_index(:n_events)
    event_int(:n_events, 3:4) = transpose(sink%event_ends(:, :n_events))
    do k = 1, n_rows
      call put_codes(trim(scene%row_name(k)), row_name_codes(:, k))
    end do
  end subroutine run_scene

  !> simulate's error out: info(1) its status, the message in text_codes(:info(6), 1) (cut
  !> to the room given). True when there was one.
  logical function put_error(error, info, text_codes)
    type(error_type), allocatable, intent(in) :: error
    integer(c_int), intent(inout) :: info(:), text_codes(:, :)
    put_error = allocated(error)
    if (.not. put_error) return
    info(1) = int(error%status, c_int)
    info(6) = min(len(error%message), size(text_codes, 1))
    call put_codes(error%message, text_codes(:info(6), 1))
  end function put_error

  !> Run one scene (its records as simulate takes them) n_runs times, run j with the real fields over_index(:) (1-based, in the
  !> order of field_names) set to over_values(:, j), keeping only each run's summary (a
  !> summary_sink: no samples): summary(:, j) in the order of summary_names, status(j) and
  !> message_codes(:, j) (the message's character codes, blank-padded) say how it ended. A
  !> failing run is a status, never the end of the batch.
  subroutine simulate_summaries(n, values, given, title, f1_table, f2_table, method, substeps, events, x_left_table, &
      x_right_table, n_numbers, &
      n_texts, number_room, field, index, value, text_room_in, text_field, text_index, text_end, text_blob, n_over, &
      over_index, n_runs, over_values, n_summary, summary, status, message_codes, interrupt_epoch)
    !f2py threadsafe
    !f2py integer(c_int) optional, intent(in) :: interrupt_epoch = -1
    integer(c_int), intent(in) :: n, n_over, n_runs, n_summary
    real(c_double), intent(in) :: values(n), over_values(n_over, n_runs)
    integer(c_int), intent(in) :: given(n), over_index(n_over)
    character(len=*), intent(in) :: title, f1_table, f2_table, method, substeps, events, x_left_table, x_right_table
    integer(c_int), intent(in) :: n_numbers, n_texts, number_room, text_room_in
    integer(c_int), intent(in) :: field(number_room), index(number_room), text_field(text_room_in), &
      text_index(text_room_in), text_end(text_room_in)
    real(c_double), intent(in) :: value(number_room)
    character(len=*), intent(in) :: text_blob
    real(c_double), intent(out) :: summary(n_summary, n_runs)
    integer(c_int), intent(out) :: status(n_runs)
    integer(c_int), intent(out) :: message_codes(512, n_runs)   ! 512 per run: see message_length
    integer(c_int), intent(in) :: interrupt_epoch   !< for every run: see simulate
    type(scene_input) :: base, input
    type(scene_type) :: scene
    type(run_stats) :: stats
    type(summary_sink) :: sink
    type(error_type), allocatable :: error
    character(len=message_length) :: message
    real(wp), allocatable :: final(:)
    integer :: j, k, l

    summary = ieee_value(1.0_c_double, ieee_quiet_nan)
    message_codes = ichar(' ')
    status = status_input
    if (.not. field_count_ok(n, status(1), message)) then
      call put_codes(message, message_codes(:, 1))
      return
    end if
    if (n_summary < size(summary_names) .or. any(over_index < 1 .or. over_index > n)) then
      message = 'internal: bad summary size or override index'
      call put_codes(message, message_codes(:, 1))
      return
    end if
    base = flat_input(values, given, title, f1_table, f2_table, method, substeps, events, x_left_table, x_right_table)
    call apply_scene_assignments(base, n_numbers, n_texts, field, index, value, text_field, text_index, &
      text_end, text_blob, error)
    if (allocated(error)) then
      status = int(error%status, c_int)
      call put_codes(error%message, message_codes(:, 1))
      return
    end if
    call catch_interrupts()
    do j = 1, n_runs
      if (interrupt_epoch >= 0 .and. interrupt_count() /= interrupt_epoch) then
        ! An interrupt since the caller's epoch ends the batch before its next run: a run
        ! shorter than a checkpoint (4096 steps) never looks, and the batch ran to its end.
        call raise(error, status_interrupted, 'interrupted before run ' // trim(fmt(j)) // ' of the batch')
      else
        input = base
        input%value(over_index) = real(over_values(:, j), wp)
        input%given(over_index) = .true.
        call prepare_scene(input, scene, error)
      end if
      ! Past two bodies, x3_end v3_end .. xN_end vN_end follow the named columns.
      if (.not. allocated(error) .and. n_summary /= size(summary_names) + 2 * max(0, scene%n_bodies - 2)) &
        call raise(error, status_input, 'internal: the summary has room for ' // trim(fmt(n_summary)) // &
          ' columns, not the named ones and two per body past the second')
      if (.not. allocated(error)) then
        sink = summary_sink(n_bodies=scene%n_bodies)
        call run(scene, sink, stats, error, int(interrupt_epoch))
      end if
      if (failed(error, status(j), message)) then
        call put_codes(message, message_codes(:, j))
        ! An interrupt ends the batch: the runs not made say so too.
        if (status(j) == status_interrupted) then
          status(j + 1:) = status_interrupted
          exit
        end if
        cycle
      end if
      ! (x1 v1 x2 v2 of the full row of one, two or N bodies, the ledger at row_ledger's)
      final = final_row(stats)
      l = row_ledger(scene%n_bodies)
      summary(:size(summary_names), j) = [final([2, 3, 4, 5, l + 1]), &
        real(sum(stats%row_events(class_impact, :)), wp), &
        real([(impacts_on(stats, scene%row_name, event_names(k)), k = event_impact + 1, event_rest)], wp), &
        sink%rest_time(final), final([l + 5, l + 4]), &
        stats%max_residual, real(stats%steps, wp), final([l + 2, l + 6])]
      ! A one-body scene has no x2_end, v2_end.
      if (scene%n_bodies == 1) summary(3:4, j) = ieee_value(1.0_c_double, ieee_quiet_nan)
      summary(size(summary_names) + 1:, j) = final(6:2 * scene%n_bodies + 1)
    end do
  end subroutine simulate_summaries

  !> A scene's records (and, for more than two bodies, its arrays: one or two come as the
  !> tutorial's fields, settled by settle_scene) assigned onto its flat fields, a chain's
  !> arrays then settled as settle_scene does.
  subroutine apply_scene_assignments(input, n_numbers, n_texts, field, index, value, text_field, text_index, &
      text_end, text_blob, error)
    type(scene_input), intent(inout) :: input
    integer(c_int), intent(in) :: n_numbers, n_texts, field(:), index(:), text_field(:), text_index(:), text_end(:)
    real(c_double), intent(in) :: value(:)
    character(len=*), intent(in) :: text_blob
    type(error_type), allocatable, intent(out) :: error
    call apply_assignments(input, .false., n_numbers, n_texts, field, index, value, text_field, text_index, &
      text_end, text_blob, error)
    if (allocated(error)) return
    if (any(field(:n_numbers) <= id_r_meet) .or. any(text_field(:n_texts) <= id_r_meet)) call settle_chain(input, error)
  end subroutine apply_scene_assignments

  !> Assignments (read_scene's form; texts as one blob, text k ending at text_end(k)) made
  !> to input, their ids, indices and ends checked first; with records_only, only the
  !> record fields may be assigned.
  subroutine apply_assignments(input, records_only, n_numbers, n_texts, field, index, value, text_field, &
      text_index, text_end, text_blob, error)
    type(scene_input), intent(inout) :: input
    logical, intent(in) :: records_only
    integer(c_int), intent(in) :: n_numbers, n_texts, field(:), index(:), text_field(:), text_index(:), text_end(:)
    real(c_double), intent(in) :: value(:)
    character(len=*), intent(in) :: text_blob
    type(error_type), allocatable, intent(out) :: error
    integer :: k, start, first
    if (n_numbers > size(field) .or. n_texts > size(text_field)) then
      call raise(error, status_input, 'internal: more assignments counted than given')
      return
    end if
    ! (an array's element or a record is counted from 1; a scalar's index is 0)
    first = merge(id_r_meet + 1, 1, records_only)
    if (any(field(:n_numbers) < first .or. field(:n_numbers) > n_ids .or. index(:n_numbers) < 0 .or. &
        (field(:n_numbers) > id_arrays .and. field(:n_numbers) /= id_r_meet .and. index(:n_numbers) < 1)) .or. &
        any(text_field(:n_texts) < first .or. text_field(:n_texts) > n_ids .or. &
        (text_field(:n_texts) > id_arrays .and. text_index(:n_texts) < 1)) .or. &
        any(text_end(:n_texts) < 0 .or. text_end(:n_texts) > len(text_blob))) then
      call raise(error, status_input, 'internal: a field id, index or text end out of range')
      return
    end if
    do k = 1, n_numbers
      call assign_number(input, field(k), index(k), real(value(k), wp))
    end do
    start = 1
    do k = 1, n_texts
      call assign_text(input, text_field(k), text_index(k), text_blob(start:text_end(k)))
      start = text_end(k) + 1
    end do
  end subroutine apply_assignments

  !> Catch SIGINT from now on (impact1d_interrupt) and return the interrupts counted so far:
  !> the epoch a caller passes to the runs it starts (a sweep, to those its workers start),
  !> so that an interrupt after this call ends them even if it comes before they start.
  subroutine interrupt_epoch_now(epoch)
    integer(c_int), intent(out) :: epoch
    call catch_interrupts()
    epoch = interrupt_count()
  end subroutine interrupt_epoch_now

  !> Names of simulate_summaries' rows, space separated.
  subroutine summary_column_names(names)
    character(len=1024), intent(out) :: names
    names = joined(summary_names)
  end subroutine summary_column_names

  !> A scene's fields as the flat layer gets them (given: non-zero where set).
  pure function flat_input(values, given, title, f1_table, f2_table, method, substeps, events, x_left_table, &
      x_right_table) result(input)
    real(c_double), intent(in) :: values(n_real)
    integer(c_int), intent(in) :: given(n_real)
    character(len=*), intent(in) :: title, f1_table, f2_table, method, substeps, events, x_left_table, x_right_table
    type(scene_input) :: input
    input%value = real(values, wp)
    input%given = given /= 0
    call set_text(input, i_title, title)
    call set_text(input, i_f1_table, f1_table)
    call set_text(input, i_f2_table, f2_table)
    call set_text(input, i_method, method)
    call set_text(input, i_substeps, substeps)
    call set_text(input, i_events, events)
    call set_text(input, i_x_left_table, x_left_table)
    call set_text(input, i_x_right_table, x_right_table)
  end function flat_input

  !> A text as character codes (byte values, 0 to 255), blank padded or cut to size(codes).
  pure subroutine put_codes(text, codes)
    character(len=*), intent(in) :: text
    integer(c_int), intent(out) :: codes(:)
    integer :: k
    codes = ichar(' ')
    do k = 1, min(len(text), size(codes))
      codes(k) = ichar(text(k:k))
    end do
  end subroutine put_codes

  !> Words separated by single spaces (how names cross to Python), as long as the flat
  !> API's longest names (input_field_names'; no function returns a deferred-length string:
  !> see impact1d_error's fmt).
  pure function joined(words) result(out)
    character(len=*), intent(in) :: words(:)
    character(len=2048) :: out
    character(len=:), allocatable :: text
    integer :: k
    text = ''
    do k = 1, size(words)
      text = text // ' ' // trim(words(k))
    end do
    out = adjustl(text)
  end function joined

  logical function field_count_ok(n, status, message)
    integer(c_int), intent(in) :: n
    integer(c_int), intent(out) :: status
    character(len=*), intent(out) :: message
    field_count_ok = n == n_real
    status = status_ok
    message = ''
    if (.not. field_count_ok) then
      status = status_input
      write(message, '(a, i0, a, i0)') 'internal: ', n, ' scene fields passed, expected ', n_real
    end if
  end function field_count_ok

  logical function failed(error, status, message)
    type(error_type), allocatable, intent(in) :: error
    integer(c_int), intent(out) :: status
    character(len=*), intent(out) :: message
    failed = allocated(error)
    status = status_ok
    message = ''
    if (failed) then
      status = int(error%status, c_int)
      message = error%message
    end if
  end function failed
end module impact1d_api
