!> Reading scenes: the namelist format, the tutorial's VisSim-style parameter files and
!> force tables. Every problem comes back as an input error naming the file, line or variable.
module impact1d_io
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, raise, status_input, fmt
  use impact1d_scene, only: tutorial_bodies
  use impact1d_scene, only: scene_input, scene_type, build_scene, validate, set_text, n_real, n_text, &
    real_names, text_names, i_m1, i_m2, i_mu1, i_mu2, i_g, i_r_left, i_r_right, i_r_min, i_r_max, i_x_left, i_x_right, &
    i_d_min, i_d_max, i_x1, i_x2, i_v1, i_v2, i_f1, i_f2, i_title, i_f1_table, i_f2_table, i_method, &
    i_substeps, i_events
  use impact1d_forcing, only: table_type
  use impact1d_fields, only: n_arrays, array_names, array_groups, array_is_text, n_contact_fields, contact_fields, &
    n_spring_fields, spring_fields, n_sine_fields, sine_fields, friction_fields, r_name, record_input, text_item, a_f_table
  use impact1d_chain, only: settle_chain, validate_chain, slot_of, mechanism_records, id_arrays, id_r_meet, &
    id_contact, id_spring, id_sine, id_friction, n_ids, n_bodies_of, check_start
  use impact1d_files, only: check_input_file
  implicit none
  private
  public :: read_scene_file, prepare_scene, read_table, lower, read_body_list

  character(len=*), parameter :: known_groups(12) = [character(len=8) :: &
    'scene', 'bodies', 'walls', 'link', 'initial', 'forces', 'springs', 'run', 'contact', 'spring', 'sine', 'friction']
  !> The groups that may be given any number of times, each occurrence a record.
  integer, parameter :: g_contact = 9, g_spring = 10, g_sine = 11, g_friction = 12, g_run = 8
  !> Each group's variables: which group a name belongs to, and the message about a misspelt one.
  character(len=*), parameter :: group_variables(size(known_groups)) = [character(len=176) :: &
    'title', 'm1, m2, mu1, mu2, mus1, mus2, g', 'x_left, r_left, x_right, r_right, x_left_v, x_left_amp, ' // &
    'x_left_period, x_left_phase, x_right_v, x_right_amp, x_right_period, x_right_phase, x_left_table, ' // &
    'x_right_table', 'd_min, r_min, d_max, r_max', &
    'x1, v1, x2, v2', 'f1, f2, f1_table, f2_table, f1_amp, f1_period, f1_phase, f2_amp, f2_period, f2_phase', &
    'k1, x1_rest, c1, k2, x2_rest, c2, k12, d_rest, c12', &
    't_end, dt, dt_out, method, zero_vel, max_rows, max_impulses, max_step_events, substeps, events, max_events, ' // &
    'bodies_out', &
    'a, b, d_min, r_min, d_max, r_max, name, k, c, ground_v, ground_amp, ground_period, ground_phase, ground_table, ' // &
      'ratio', &
    'a, b, k, d_rest, c, ground_v, ground_amp, ground_period, ground_phase, ground_table, ratio', 'body, amp, period, phase', &
    'a, b, mu, mus, normal, name']

  !> The tutorial's parameter files list these, in its Table 1 order; g is 10 there.
  integer, parameter :: dat_order(17) = [i_m1, i_m2, i_mu1, i_r_left, i_r_right, i_r_min, &
    i_r_max, i_x_left, i_x_right, i_d_min, i_d_max, i_x1, i_x2, i_v1, i_v2, i_f1, i_f2]
  real(wp), parameter :: dat_gravity = 10.0_wp
  character(len=*), parameter :: letters = 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ'
  character(len=*), parameter :: name_chars = letters // '0123456789_'
  !> What read_numbers found: every number, text that is not numbers, or a value missing.
  integer, parameter :: number_ok = 0, number_malformed = 1, number_null = 2
  !> The largest repeat count of a list ('r*c'): no scene has a million bodies.
  integer, parameter :: max_repeat = 1000000

  !> A namelist file while it is parsed: its text (join_lines) and where each line starts,
  !> the group open (0: none), the line of each group and of each variable given (0: none).
  type :: namelist_text
    character(len=:), allocatable :: path, flat
    integer, allocatable :: starts(:)
    integer :: open_group = 0
    integer :: group_line(size(known_groups)) = 0
    integer :: given_line(n_ids) = 0
  end type namelist_text

contains

  !> Read a scene file: '.dat' is a VisSim-style parameter file, anything else a namelist.
  !> Checks what can be checked before the &run values are final.
  subroutine read_scene_file(path, input, error)
    character(len=*), intent(in) :: path
    type(scene_input), intent(out) :: input
    type(error_type), allocatable, intent(out) :: error
    integer :: n, k
    n = len_trim(path)
    if (n == 0) then
      call raise(error, status_input, 'no scene file given')
      return
    end if
    do k = 1, n_text      ! every text exists, absent ('') until the file gives it
      call set_text(input, k, '')
    end do
    if (n > 4) then
      if (path(n - 3:n) == '.dat') then
        call read_dat(trim(path), input, error)
      else
        call read_namelist(trim(path), input, error)
      end if
    else
      call read_namelist(trim(path), input, error)
    end if
    if (allocated(error)) return
    input%source = trim(path)
    call settle_chain(input, error)
    if (.not. allocated(error)) call validate(input, .false., error)
    if (.not. allocated(error)) call validate_chain(input, error)
    if (allocated(error)) error%message = trim(path) // ': ' // error%message
  end subroutine read_scene_file

  !> Read the force tables an input names, check it whole (its records too: a scene from
  !> the flat API has not been read from a file), then build the model from its records.
  subroutine prepare_scene(input, scene, error)
    type(scene_input), intent(in) :: input
    type(scene_type), intent(out) :: scene
    type(error_type), allocatable, intent(out) :: error
    type(table_type), allocatable :: tables(:)
    type(mechanism_records) :: records
    character(len=:), allocatable :: path
    integer :: i
    allocate(tables(max(tutorial_bodies, n_bodies_of(input))))
    do i = 1, size(tables)
      ! Body i's table: the tutorial's f1_table, f2_table, or f_table(i) of N > 2 bodies.
      if (input%chain%n_bodies > tutorial_bodies) then
        if (input%chain%array(a_f_table)%n < i) cycle
        path = trim(input%chain%array(a_f_table)%t(i)%s)
      else
        if (i > tutorial_bodies) cycle
        path = trim(input%text(i_f1_table + i - 1)%s)
      end if
      if (len(path) == 0) cycle
      call read_table(path, tables(i), error)
      if (allocated(error)) then
        if (input%chain%n_bodies > tutorial_bodies) then
          error%message = 'f_table(' // trim(fmt(i)) // '): ' // error%message
        else
          error%message = 'f' // trim(fmt(i)) // '_table: ' // error%message
        end if
        return
      end if
    end do
    ! The records' ends index the bodies: checked (validate_chain) before they are made,
    ! after the scene's values (validate, as build_scene does: its messages come first).
    call validate(input, .true., error)
    if (.not. allocated(error)) call validate_chain(input, error, records)
    if (allocated(error)) return
    call read_ground_tables(input, records, error)
    if (allocated(error)) return
    call build_scene(input, tables, records, scene, error, validated=.true.)
  end subroutine prepare_scene

  !> The tables that move ground ends (the records' ground_table), read as
  !> force tables are; the start checked again with them (w(0) counts table(0)). A scene
  !> that names none reads nothing.
  subroutine read_ground_tables(input, records, error)
    type(scene_input), intent(in) :: input
    type(mechanism_records), intent(inout) :: records
    type(error_type), allocatable, intent(inout) :: error
    integer :: k
    if (all([(.not. allocated(records%contact_table_path(k)%s), k = 1, records%n_contacts)]) .and. &
      all([(.not. allocated(records%element_table_path(k)%s), k = 1, records%n_elements)])) return
    allocate(records%contact_table(records%n_contacts), records%element_table(records%n_elements))
    do k = 1, records%n_contacts
      if (.not. allocated(records%contact_table_path(k)%s)) cycle
      call read_table(records%contact_table_path(k)%s, records%contact_table(k), error)
      if (allocated(error)) then
        if (k <= count([input%given(i_x_left), input%given(i_x_right)])) then
          ! A wall's table: named as the user wrote it (the walls are the first records,
          ! the left one first: input_records), not by the record made of it.
          error%message = trim(merge('x_left_table ', 'x_right_table', k == 1 .and. input%given(i_x_left))) // &
            ': ' // error%message
        else
          error%message = 'the contact ''' // trim(records%contact_name(k)) // '''s ground_table: ' // error%message
        end if
        return
      end if
    end do
    do k = 1, records%n_elements
      if (.not. allocated(records%element_table_path(k)%s)) cycle
      call read_table(records%element_table_path(k)%s, records%element_table(k), error)
      if (allocated(error)) then
        error%message = '&spring ground_table: ' // error%message
        return
      end if
    end do
    records%tables_read = .true.
    call check_start(input, records, error)
  end subroutine read_ground_tables

  !> A namelist scene, read by its own parser: gfortran's namelist reader took an '&initial'
  !> inside a quoted title for the group, and passed over a variable with no value
  !> ('v1 = ,', 'v2 = 1*', 'f2 /') or given twice. Groups '&name ... /' ('$name', and '&end'
  !> or '$end' for '/'), items 'name = value' apart by blanks, commas or semicolons, '!'
  !> comments. Quoted text ('...' or "...", a doubled quote standing for one) is never
  !> scanned for groups, ends or separators. A number is read as list-directed input reads
  !> it: the same digits give the same double as the namelist reader did.
  subroutine read_namelist(path, input, error)
    character(len=*), intent(in) :: path
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(out) :: error
    character(len=:), allocatable :: lines(:)
    type(namelist_text) :: nml
    integer :: j, k

    call read_all_lines(path, lines, error)
    if (allocated(error)) return
    nml%path = path
    call join_lines(lines, nml%flat, nml%starts, k)
    if (k > 0) then
      call raise(error, status_input, path // ':' // trim(fmt(k)) // ': a quote opened on this line is not ' // &
        'closed on it (quoted text is one line; a quote inside it is written twice: ''it''''s'')')
      return
    end if
    if (len_trim(nml%flat) == 0) then
      call raise(error, status_input, path // ': the file is empty')
      return
    end if
    j = 1
    do while (j <= len(nml%flat))
      call next_item(nml, j, input, error)
      if (allocated(error)) return
    end do
    if (nml%open_group > 0) then
      call raise(error, status_input, path // ':' // trim(fmt(nml%group_line(nml%open_group))) // ': the group &' // &
        trim(known_groups(nml%open_group)) // ' has no closing ''/'' (every group ends with /)')
      return
    end if
    do k = 1, size(known_groups)
      if (any(trim(known_groups(k)) == ['bodies ', 'initial', 'run    ']) .and. nml%group_line(k) == 0) then
        call raise(error, status_input, path // ': the required group &' // trim(known_groups(k)) // ' is missing')
        return
      end if
    end do
  end subroutine read_namelist

  !> The file's lines as one text with the '!' comments cut, tabs and carriage returns as
  !> blanks (outside quotes) and a blank for each line's end; starts(l) is where line l
  !> begins (starts(size(lines) + 1) one past the end). open_quote is the first line whose
  !> quote is not closed on it, else 0.
  pure subroutine join_lines(lines, flat, starts, open_quote)
    character(len=*), intent(in) :: lines(:)
    character(len=:), allocatable, intent(out) :: flat
    integer, allocatable, intent(out) :: starts(:)
    integer, intent(out) :: open_quote
    character :: quote, c
    integer :: l, k, at
    allocate(character(len=sum(len_trim(lines)) + size(lines)) :: flat)
    allocate(starts(size(lines) + 1))
    open_quote = 0
    at = 1
    do l = 1, size(lines)
      starts(l) = at
      quote = ' '
      do k = 1, len_trim(lines(l))
        c = lines(l)(k:k)
        if (quote /= ' ') then
          if (c == quote) quote = ' '
        else if (c == '!') then
          exit
        else if (c == '''' .or. c == '"') then
          quote = c
        else if (c == achar(9) .or. c == achar(13)) then
          c = ' '
        end if
        flat(at:at) = c
        at = at + 1
      end do
      if (quote /= ' ' .and. open_quote == 0) open_quote = l
      flat(at:at) = ' '
      at = at + 1
    end do
    starts(size(lines) + 1) = at
    flat = flat(:at - 1)
  end subroutine join_lines

  !> The item at or after j: a group's start or end, or an assignment; j moves past it.
  subroutine next_item(nml, j, input, error)
    type(namelist_text), intent(inout) :: nml
    integer, intent(inout) :: j
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(inout) :: error
    integer :: k, line
    ! Between a group's items, commas and semicolons are separators; outside, text.
    k = verify(nml%flat(j:), merge(' ,;', '   ', nml%open_group > 0))
    if (k == 0) then
      j = len(nml%flat) + 1
      return
    end if
    j = j + k - 1
    if (nml%flat(j:j) == '&' .or. nml%flat(j:j) == '$') then
      call group_mark(nml, j, input, error)
    else if (nml%open_group == 0) then
      line = line_at(nml, j)
      call raise(error, status_input, nml%path // ':' // trim(fmt(line)) // ': text outside any group: ''' // &
        trim(nml%flat(j:nml%starts(line + 1) - 1)) // '''')
    else if (nml%flat(j:j) == '/') then
      nml%open_group = 0
      j = j + 1
    else
      call assignment(nml, j, input, error)
    end if
  end subroutine next_item

  !> '&name' (or '$name') at j: a group opens, or '&end' closes the open one.
  subroutine group_mark(nml, j, input, error)
    type(namelist_text), intent(inout) :: nml
    integer, intent(inout) :: j
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(inout) :: error
    character(len=:), allocatable :: name
    integer :: finish, group, k, line
    finish = name_end(nml%flat, j + 1)
    name = lower(nml%flat(j + 1:finish))
    line = line_at(nml, j)
    j = finish + 1
    if (name == 'end' .and. nml%open_group > 0) then
      nml%open_group = 0
      return
    end if
    if (nml%open_group > 0) then
      call raise(error, status_input, nml%path // ':' // trim(fmt(line)) // ': the group &' // &
        trim(known_groups(nml%open_group)) // ' (line ' // trim(fmt(nml%group_line(nml%open_group))) // &
        ') has no closing ''/'' before &' // name)
      return
    end if
    group = 0
    do k = 1, size(known_groups)
      if (trim(known_groups(k)) == name) group = k
    end do
    if (group == 0) then
      call raise(error, status_input, nml%path // ':' // trim(fmt(line)) // ': unknown group &' // name // &
        ' (groups: &scene &bodies &walls &link &initial &forces &springs &run, and as often as wanted ' // &
        '&contact &spring &sine &friction)')
    else if (group >= g_contact) then
      ! Each occurrence is a record of its own; "given twice" applies within it.
      call new_record(input, group, line)
      nml%given_line(id_contact + 1:) = 0
      nml%group_line(group) = line
      nml%open_group = group
    else if (nml%group_line(group) > 0) then
      call raise(error, status_input, nml%path // ':' // trim(fmt(line)) // ': the group &' // name // &
        ' is given twice (lines ' // trim(fmt(nml%group_line(group))) // ' and ' // trim(fmt(line)) // ')')
    else
      nml%group_line(group) = line
      nml%open_group = group
    end if
  end subroutine group_mark

  !> 'name = value' at j, inside the open group: the variable must be one of the group's,
  !> given once, with a value.
  subroutine assignment(nml, j, input, error)
    type(namelist_text), intent(inout) :: nml
    integer, intent(inout) :: j
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(inout) :: error
    character(len=:), allocatable :: name, value, context
    integer :: finish, field, k, line
    logical :: bodies_out
    line = line_at(nml, j)
    context = nml%path // ':' // trim(fmt(line)) // ': in &' // trim(known_groups(nml%open_group)) // ': '
    finish = name_end(nml%flat, j)
    name = lower(nml%flat(j:finish))
    field = field_index(name, nml%open_group)
    ! (&run bodies_out: a list of bodies in one line, read by read_body_list as the CLI's
    ! --bodies-out is; the flat API gives it as field id_bodies_out, one element a body)
    bodies_out = name == 'bodies_out' .and. nml%open_group == g_run
    if (field == 0 .and. .not. bodies_out) then
      k = scan(nml%flat(j:) // ' ', ' ,;=/')
      call raise(error, status_input, context // 'unknown variable ''' // nml%flat(j:j + k - 2) // ''' (&' // &
        trim(known_groups(nml%open_group)) // ' has: ' // trim(group_variables(nml%open_group)) // ')' // &
        trim(arrays_of(nml%open_group)))
      return
    end if
    k = verify(nml%flat(finish + 1:) // '=', ' ') + finish
    if (.not. is_at(nml%flat, k, '=')) then
      if (k > len(nml%flat) .or. scan(nml%flat(k:min(k, len(nml%flat))), ',;/&$' // letters) > 0) then
        call raise(error, status_input, context // name // ' has no value (write ' // name // ' = ...)')
      else
        call raise(error, status_input, context // name // ' is followed by ''' // &
          trim(nml%flat(k:nml%starts(line_at(nml, k) + 1) - 1)) // ''' where ''='' belongs')
      end if
      return
    end if
    if (.not. bodies_out) then
      if (nml%given_line(field) > 0) then
        call raise(error, status_input, context // name // ' is given twice (lines ' // &
          trim(fmt(nml%given_line(field))) // ' and ' // trim(fmt(line)) // ')')
        return
      end if
    end if
    j = value_end(nml%flat, k + 1, nml%open_group)
    value = trim(adjustl(nml%flat(k + 1:j - 1)))
    if (len(value) > 0) then
      if (scan(value(len(value):), ',;') > 0) value = trim(value(:len(value) - 1))
    end if
    if (bodies_out) then
      call take_bodies_out(value, context, input, error)
      return
    end if
    call take_value(nml%path, field, name, value, input, error)
    if (allocated(error)) error%message = context // error%message
    nml%given_line(field) = line
  end subroutine assignment

  !> &run bodies_out = 1, 10, 20: the bodies whose x and v the output has (impact1d_output's
  !> check_bodies_out checks them against the scene).
  subroutine take_bodies_out(value, context, input, error)
    character(len=*), intent(in) :: value, context
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(inout) :: error
    logical :: ok
    if (allocated(input%bodies_out)) then
      call raise(error, status_input, context // 'bodies_out is given twice')
      return
    end if
    call read_body_list(value, input%bodies_out, ok)
    if (.not. ok) call raise(error, status_input, context // 'bodies_out = ' // value // &
      ' is not a list of body numbers (write bodies_out = 1, 10, 20)')
  end subroutine take_bodies_out

  !> A list of body numbers, whole numbers separated by commas ('1, 10, 20'; &run bodies_out,
  !> --bodies-out); ok false for anything else (bodies then not allocated).
  subroutine read_body_list(text, bodies, ok)
    character(len=*), intent(in) :: text
    integer, allocatable, intent(out) :: bodies(:)
    logical, intent(out) :: ok
    integer :: ios, i
    ok = len_trim(text) > 0 .and. verify(text, '0123456789, ') == 0 .and. index(text, ',,') == 0
    if (.not. ok) return
    allocate(bodies(count([(text(i:i) == ',', i = 1, len(text))]) + 1))
    read(text, *, iostat=ios) bodies
    ok = ios == 0
    if (.not. ok) deallocate(bodies)
  end subroutine read_body_list

  !> Where the value that starts at k ends: at the next '/', group mark or item outside
  !> quotes. An item starts at a name after a comma, a name followed by '=', or a variable
  !> of the group; a value is anything else ('1.0 2.0', '(1.0, 2.0)' and '0,5' are one
  !> value each, so that the message can quote it).
  pure integer function value_end(flat, k, group) result(e)
    character(len=*), intent(in) :: flat
    integer, intent(in) :: k, group
    character :: quote, c
    logical :: boundary, after_comma
    integer :: finish, next
    quote = ' '
    boundary = .true.
    after_comma = .false.
    do e = k, len(flat)
      c = flat(e:e)
      if (quote /= ' ') then
        if (c == quote) quote = ' '
        boundary = .false.
        after_comma = .false.
        cycle
      end if
      if (c == '/') return
      if (boundary .and. (c == '&' .or. c == '$') .and. e < len(flat)) then
        if (index(letters, flat(e + 1:e + 1)) > 0) return
      end if
      if (boundary .and. index(letters, c) > 0) then
        finish = name_end(flat, e)
        next = verify(flat(finish + 1:) // '=', ' ') + finish
        if (is_at(flat, next, '=')) return
        ! (an array's NaN or Inf after a comma is one of its items, not a name)
        if (after_comma .and. .not. any(lower(flat(e:finish)) == ['nan     ', 'inf     ', 'infinity'])) return
        if (field_index(lower(flat(e:finish)), group) > 0) return
      end if
      if (c == '''' .or. c == '"') quote = c
      if (c == ',' .or. c == ';') then
        after_comma = .true.
      else if (c /= ' ') then
        after_comma = .false.
      end if
      boundary = scan(c, ' ,;') > 0
    end do
    e = len(flat) + 1
  end function value_end

  !> Put one variable's value into the input: a real must be one number, a text quoted,
  !> an array a list of them (repeat counts 'r*c' allowed, nulls not), a record's field
  !> into the record open.
  subroutine take_value(path, field, name, value, input, error)
    character(len=*), intent(in) :: path, name, value
    integer, intent(in) :: field
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(inout) :: error
    character(len=:), allocatable :: text
    real(wp) :: number
    integer :: j
    if (len(value) == 0) then
      call raise(error, status_input, name // ' has no value (write ' // name // ' = ...)')
    else if (value(len(value):) == '*' .and. verify(value(:len(value) - 1), '0123456789') == 0) then
      ! 'r*' alone, a repeat count of nothing, is a null.
      call raise(error, status_input, name // ' = ' // value // ' has no value (a null: write ' // name // ' = ...)')
    else if (field <= n_real .and. shared_array(name) > 0 .and. several(value)) then
      call take_array(path, shared_array(name), name, value, input, error)
    else if (field <= n_real) then
      call read_scalar(name, value, number, error)
      if (allocated(error)) return
      input%value(field) = number
      input%given(field) = .true.
    else if (field <= id_arrays) then
      call read_text(name, value, text, error)
      if (allocated(error)) return
      if (field - n_real == i_title) then
        call set_text(input, i_title, text)
      else
        call set_text(input, field - n_real, trim(resolved_text(path, field - n_real, text)))
      end if
    else if (field < id_r_meet) then
      call take_array(path, field - id_arrays, name, value, input, error)
    else if (field == id_r_meet) then
      call read_scalar(name, value, input%chain%r_meet, error)
      input%chain%has_r_meet = .true.
    else
      if (field > id_friction) then
        call take_record_field(path, name, value, field - id_friction, input%chain%frictions, error)
      else if (field > id_sine) then
        call take_record_field(path, name, value, field - id_sine, input%chain%sines, error)
      else if (field > id_spring) then
        call take_record_field(path, name, value, field - id_spring, input%chain%springs, error)
      else
        call take_record_field(path, name, value, field - id_contact, input%chain%contacts, error)
      end if
    end if
  end subroutine take_value

  !> One number: 'name = 'value' is not a number' (with a hint for a decimal comma) else.
  subroutine read_scalar(name, value, number, error)
    character(len=*), intent(in) :: name, value
    real(wp), intent(out) :: number
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: numbers(1)
    integer :: status
    ! In a namelist a comma always separates: '0,5' is not one number.
    status = number_malformed
    number = 0.0_wp
    if (scan(value, ',;') == 0) call read_numbers(value, numbers, status)
    if (status == number_null) then
      call raise(error, status_input, name // ' = ' // value // ' has no value (a null: write ' // name // ' = ...)')
    else if (value == '+' .or. value == '-') then
      call raise(error, status_input, '''' // name // ' = ' // value // ''' has no number after its sign')
    else if (status == number_malformed .and. decimal_comma(value)) then
      call raise(error, status_input, name // ' = ''' // value // ''' is not a number (a decimal comma? ' // &
        'write a point)')
    else if (status == number_malformed) then
      call raise(error, status_input, name // ' = ''' // value // ''' is not a number')
    else
      number = numbers(1)
    end if
  end subroutine read_scalar

  !> One quoted text.
  subroutine read_text(name, value, text, error)
    character(len=*), intent(in) :: name, value
    character(len=:), allocatable, intent(out) :: text
    type(error_type), allocatable, intent(inout) :: error
    logical :: ok
    call unquote(value, text, ok)
    if (.not. ok) call raise(error, status_input, name // ' = ' // value // ' is not one quoted text (write ' // &
      name // ' = ''...'')')
  end subroutine read_text

  !> Text field i (not the title) as kept: keywords in lower case (any letter case is read),
  !> paths relative to the scene file's folder.
  pure function resolved_text(path, i, text) result(kept)
    character(len=*), intent(in) :: path, text
    integer, intent(in) :: i
    character(len=len(path) + len(text)) :: kept     ! blank padded: callers trim
    if (any(i == [i_method, i_substeps, i_events])) then
      kept = lower(text)
    else
      kept = beside(path, text)
    end if
  end function resolved_text

  !> An array's value: a list of numbers or quoted texts (r*c: c repeated r times), no null.
  subroutine take_array(path, j, name, value, input, error)
    character(len=*), intent(in) :: path, name, value
    integer, intent(in) :: j
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(inout) :: error
    type(text_item), allocatable :: items(:)
    character(len=:), allocatable :: text
    character(len=32) :: spelled
    integer :: k
    logical :: null
    call split_items(value, items, null)
    if (null) then
      call raise(error, status_input, name // ' = ' // value // ' has a null (an empty item or ''r*'' with ' // &
        'no value): write every value')
      return
    end if
    associate (array => input%chain%array(j))
      array%n = size(items)
      if (array_is_text(j)) then
        allocate(array%t(size(items)))
      else
        allocate(array%v(size(items)))
      end if
      do k = 1, size(items)
        ! (an item's error names it as name(k))
        write(spelled, '(a, "(", i0, ")")') name, k
        if (array_is_text(j)) then
          call read_text(trim(spelled), items(k)%s, text, error)
          if (.not. allocated(error)) array%t(k)%s = trim(resolved_text(path, i_f1_table, text))
        else
          call read_scalar(trim(spelled), items(k)%s, array%v(k), error)
        end if
        if (allocated(error)) return
      end do
    end associate
  end subroutine take_array

  !> Field f of the record open (the last of records): a number, or the contact's name, or
  !> the ground_table's path (relative to the scene file's folder, as force tables).
  subroutine take_record_field(path, name, value, f, records, error)
    character(len=*), intent(in) :: path, name, value
    integer, intent(in) :: f
    type(record_input), intent(inout) :: records(:)
    type(error_type), allocatable, intent(inout) :: error
    character(len=:), allocatable :: text
    associate (rec => records(size(records)))
      if (name == 'name') then
        call read_text(name, value, text, error)
        if (allocated(error)) return
        rec%name = text
        rec%given(f) = .true.
      else if (name == 'ground_table') then
        call read_text(name, value, text, error)
        if (allocated(error)) return
        rec%table = trim(resolved_text(path, i_f1_table, text))
        rec%given(f) = .true.
      else
        call read_scalar(name, value, rec%value(f), error)
        rec%given(f) = .not. allocated(error)
      end if
    end associate
  end subroutine take_record_field

  !> A record of group (&contact, &spring, &sine or &friction) opens at line.
  pure subroutine new_record(input, group, line)
    type(scene_input), intent(inout) :: input
    integer, intent(in) :: group, line
    if (group == g_contact) then
      call append_record(input%chain%contacts, line)
    else if (group == g_spring) then
      call append_record(input%chain%springs, line)
    else if (group == g_sine) then
      call append_record(input%chain%sines, line)
    else
      call append_record(input%chain%frictions, line)
    end if
  end subroutine new_record

  !> One more record, opened at line.
  pure subroutine append_record(records, line)
    type(record_input), allocatable, intent(inout) :: records(:)
    integer, intent(in) :: line
    type(record_input) :: rec
    rec%line = line
    if (.not. allocated(records)) allocate(records(0))
    records = [records, rec]
  end subroutine append_record

  !> The items of a list: apart by commas, semicolons or blanks, outside quotes; 'r*c' is
  !> c r times. null: an empty item (two commas, a comma first or last) or 'r*' alone.
  pure subroutine split_items(value, items, null)
    character(len=*), intent(in) :: value
    type(text_item), allocatable, intent(out) :: items(:)
    logical, intent(out) :: null
    integer :: k, finish, star, repeat, ios, r, n
    logical :: expect
    ! Room doubled when full (appending one at a time copied every item so far: quadratic,
    ! 10 s of a 10,000-body scene's reading).
    allocate(items(16))
    n = 0
    null = .false.
    expect = .true.
    k = 1
    do while (k <= len(value))
      if (value(k:k) == ' ') then
        k = k + 1
      else if (scan(value(k:k), ',;') > 0) then
        null = null .or. expect
        expect = .true.
        k = k + 1
      else
        finish = item_end(value, k)
        star = index(value(k:finish), '*')
        repeat = 1
        if (star > 1 .and. verify(value(k:k + star - 2), '0123456789') == 0) then
          ! (a count beyond max_repeat stays in the item, which is then not a number)
          read(value(k:k + star - 2), '(i20)', iostat=ios) repeat
          if (ios == 0 .and. repeat >= 1 .and. repeat <= max_repeat) then
            null = null .or. k + star > finish
            k = k + star
          else
            repeat = 1
          end if
        end if
        if (n + repeat > size(items)) call resize_items(items, n, max(2 * size(items), n + repeat))
        do r = 1, repeat
          items(n + r)%s = value(k:finish)
        end do
        n = n + repeat
        expect = .false.
        k = finish + 1
      end if
    end do
    call resize_items(items, n, n)
    null = null .or. (expect .and. n > 0) .or. n == 0
  end subroutine split_items

  !> items' first n kept (moved, not copied) in an array of the given size.
  pure subroutine resize_items(items, n, capacity)
    type(text_item), allocatable, intent(inout) :: items(:)
    integer, intent(in) :: n, capacity
    type(text_item), allocatable :: resized(:)
    integer :: r
    allocate(resized(capacity))
    do r = 1, n
      call move_alloc(items(r)%s, resized(r)%s)
    end do
    call move_alloc(resized, items)
  end subroutine resize_items

  !> The last position of the item that starts at k: before the next blank, comma or
  !> semicolon outside quotes.
  pure integer function item_end(value, k)
    character(len=*), intent(in) :: value
    integer, intent(in) :: k
    character :: quote
    quote = ' '
    do item_end = k, len(value)
      if (quote /= ' ') then
        if (value(item_end:item_end) == quote) quote = ' '
      else if (scan(value(item_end:item_end), ' ,;') > 0) then
        exit
      else if (scan(value(item_end:item_end), '''"') > 0) then
        quote = value(item_end:item_end)
      end if
    end do
    item_end = item_end - 1
  end function item_end

  !> Whether a value is a list (more than one item, or a repeat count) rather than a scalar.
  pure logical function several(value)
    character(len=*), intent(in) :: value
    several = item_end(value, 1) < len(value) .or. index(value, '*') > 0
  end function several

  !> The array a tutorial name of &link or &springs also names (d_min is d_min(1)), else 0.
  pure integer function shared_array(name)
    character(len=*), intent(in) :: name
    integer :: j
    shared_array = 0
    do j = 1, n_arrays
      if (array_names(j) == name) shared_array = j
    end do
  end function shared_array

  !> ' or, for N bodies, the arrays m, mu, mus' for a group that has arrays (for messages).
  pure function arrays_of(group) result(text)
    integer, intent(in) :: group
    character(len=128) :: text     ! blank padded: callers trim
    integer :: j
    text = ''
    do j = 1, n_arrays
      if (array_groups(j) /= known_groups(group)) cycle
      if (len_trim(text) == 0) then
        text = ' or, for N bodies, the arrays ' // array_names(j)
      else
        text = trim(text) // ', ' // array_names(j)
      end if
    end do
    if (known_groups(group) == 'link') text = trim(text) // ', r_meet'
  end function arrays_of

  !> Every line of a file, as the records of an internal file (blank-padded to the longest).
  subroutine read_all_lines(path, lines, error)
    character(len=*), intent(in) :: path
    character(len=:), allocatable, intent(out) :: lines(:)
    type(error_type), allocatable, intent(out) :: error
    character(len=:), allocatable :: line
    integer :: unit, ios, n, longest
    call open_data_file(path, unit, error)
    if (allocated(error)) return
    n = 0
    longest = 1
    do
      call read_line(unit, line, ios)
      if (ios /= 0) exit
      n = n + 1
      longest = max(longest, len(line))
    end do
    allocate(character(len=longest) :: lines(n))
    rewind(unit)
    do n = 1, size(lines)
      call read_line(unit, line, ios)
      lines(n) = line
    end do
    close(unit)
  end subroutine read_all_lines

  !> Whether text has character c at position k (false beyond its end).
  pure logical function is_at(text, k, c)
    character(len=*), intent(in) :: text
    integer, intent(in) :: k
    character, intent(in) :: c
    is_at = .false.
    if (k >= 1 .and. k <= len(text)) is_at = text(k:k) == c
  end function is_at

  !> Line of position j of a namelist's joined text.
  pure integer function line_at(nml, j)
    type(namelist_text), intent(in) :: nml
    integer, intent(in) :: j
    line_at = count(nml%starts(:size(nml%starts) - 1) <= j)
  end function line_at

  !> The last position of the name (letters, digits, '_') that starts at j; j - 1 if none.
  pure integer function name_end(text, j)
    character(len=*), intent(in) :: text
    integer, intent(in) :: j
    name_end = verify(text(j:) // ' ', name_chars) + j - 2
  end function name_end

  !> Variable `name` of group `group`: 1..n_real a real field, n_real + i text field i, then
  !> the arrays, r_meet and the record fields (impact1d_chain's id_*); 0 when the group has no such variable.
  pure integer function field_index(name, group)
    character(len=*), intent(in) :: name
    integer, intent(in) :: group
    integer :: k
    field_index = 0
    if (len(name) == 0) return
    if (group == g_contact) then
      field_index = record_field(name, contact_fields, id_contact)
      return
    else if (group == g_spring) then
      field_index = record_field(name, spring_fields, id_spring)
      return
    else if (group == g_sine) then
      field_index = record_field(name, sine_fields, id_sine)
      return
    else if (group == g_friction) then
      field_index = record_field(name, friction_fields, id_friction)
      return
    end if
    if (index(', ' // trim(group_variables(group)) // ',', ', ' // name // ',') > 0) then
      field_index = slot_of(name)
    else if (name == 'r_meet' .and. known_groups(group) == 'link') then
      field_index = id_r_meet
    else
      do k = 1, n_arrays
        if (array_names(k) == name .and. array_groups(k) == known_groups(group)) field_index = id_arrays + k
      end do
    end if
  end function field_index

  !> first + k when name is fields(k), else 0.
  pure integer function record_field(name, fields, first)
    character(len=*), intent(in) :: name, fields(:)
    integer, intent(in) :: first
    integer :: k
    record_field = 0
    do k = 1, size(fields)
      if (fields(k) == name) record_field = first + k
    end do
  end function record_field

  !> The text inside one quoted string ('...' or "..."), a doubled quote read as one; ok is
  !> false for anything else (no quotes, two strings, a lone quote inside).
  pure subroutine unquote(value, text, ok)
    character(len=*), intent(in) :: value
    character(len=:), allocatable, intent(out) :: text
    logical, intent(out) :: ok
    character(len=len(value)) :: buffer
    character :: quote
    integer :: k, n, m
    text = ''
    ok = .false.
    n = len(value)
    if (n < 2) return
    quote = value(1:1)
    if ((quote /= '''' .and. quote /= '"') .or. value(n:n) /= quote) return
    m = 0
    k = 2
    do while (k < n)
      if (value(k:k) == quote) then
        if (k + 1 >= n .or. value(k + 1:k + 1) /= quote) return
        k = k + 1
      end if
      m = m + 1
      buffer(m:m) = value(k:k)
      k = k + 1
    end do
    text = buffer(:m)
    ok = .true.
  end subroutine unquote

  !> '0,5' or '-12,25': a number written with a decimal comma.
  pure logical function decimal_comma(text)
    character(len=*), intent(in) :: text
    character(len=*), parameter :: digits = '0123456789'
    integer :: c, first
    c = index(text, ',')
    first = 1
    if (len(text) > 0) then
      if (scan(text(1:1), '+-') > 0) first = 2
    end if
    decimal_comma = c > first .and. c < len(text) .and. verify(text(first:max(c - 1, 0)), digits) == 0 .and. &
      verify(text(c + 1:), digits) == 0
  end function decimal_comma

  !> The numbers of one line (a table row, a .dat entry, a namelist value) as list-directed
  !> input reads them, every one there and nothing after them. A null (', 5', '1*', a line
  !> cut short by '/') leaves its variable as it was, an uninitialised or an earlier line's
  !> value: a value that reads as the fill is read again over another fill, and one that
  !> kept both is missing.
  subroutine read_numbers(text, values, status)
    character(len=*), intent(in) :: text
    real(wp), intent(out) :: values(:)
    integer, intent(out) :: status
    real(wp) :: again(size(values)), surplus
    integer :: ios, extra
    values = huge(1.0_wp)
    read(text, *, iostat=ios) values
    again = values
    if (ios == 0 .and. any(values == huge(1.0_wp))) then
      again = -huge(1.0_wp)
      read(text, *, iostat=ios) again
    end if
    extra = -1
    if (ios == 0) read(text, *, iostat=extra) again, surplus
    status = number_malformed
    if (ios /= 0 .or. extra == 0 .or. .not. numbers_well_formed(text)) return
    status = number_null
    if (any(values == huge(1.0_wp) .and. again == -huge(1.0_wp))) return
    status = number_ok
  end subroutine read_numbers

  !> Every item of a line of numbers is written as a Fortran number: digits with at most one
  !> point, an exponent only after its letter (list-directed input reads '1+1' as 1e+1 =
  !> 10), or NaN / Inf; a repeat count 'r*' before it, nulls and a '/' ending the line
  !> are read_numbers' to judge.
  pure logical function numbers_well_formed(text)
    character(len=*), intent(in) :: text
    integer :: k, finish, star
    numbers_well_formed = .true.
    k = 1
    do while (k <= len(text))
      if (scan(text(k:k), ' ,') > 0) then
        k = k + 1
        cycle
      end if
      if (text(k:k) == '/') return
      finish = scan(text(k:) // ' ', ' ,/') + k - 2
      star = index(text(k:finish), '*')
      if (star > 0) then
        if (star < finish - k + 1) numbers_well_formed = numbers_well_formed .and. &
          well_formed_number(text(k + star:finish))
      else
        numbers_well_formed = numbers_well_formed .and. well_formed_number(text(k:finish))
      end if
      k = finish + 1
    end do
  end function numbers_well_formed

  !> [sign] digits [. digits] | [sign] . digits, then [e|d [sign] digits]; or NaN, Inf,
  !> Infinity (any letter case, signed).
  pure logical function well_formed_number(item)
    character(len=*), intent(in) :: item
    character(len=*), parameter :: digits = '0123456789'
    character(len=len(item)) :: low
    integer :: k, first, mantissa_digits, e
    low = lower(item)
    first = 1
    if (scan(low(1:1), '+-') > 0) first = 2
    well_formed_number = any(low(first:) == ['nan     ', 'inf     ', 'infinity'])
    if (well_formed_number .or. first > len(low)) return
    e = scan(low(first:), 'ed') + first - 1
    if (e < first) e = len(low) + 1
    mantissa_digits = 0
    do k = first, e - 1
      if (index(digits, low(k:k)) > 0) mantissa_digits = mantissa_digits + 1
    end do
    ! The mantissa: digits and at most one point, at least one digit.
    if (mantissa_digits == 0 .or. verify(low(first:e - 1), digits // '.') > 0 .or. &
        count([(low(k:k) == '.', k = first, e - 1)]) > 1) return
    if (e <= len(low)) then
      k = e + 1
      if (k <= len(low)) then
        if (scan(low(k:k), '+-') > 0) k = k + 1
      end if
      if (k > len(low)) return
      if (verify(low(k:), digits) > 0) return
    end if
    well_formed_number = .true.
  end function well_formed_number

  !> The tutorial's parameter file: 17 numbers, one per line, '#' starts a comment; an
  !> optional 18th entry names a table added to f1 (the tutorial's triangle.dat button).
  subroutine read_dat(path, input, error)
    character(len=*), intent(in) :: path
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(out) :: error
    integer :: unit, ios, n_read, line_number, status
    character(len=:), allocatable :: line
    real(wp) :: value(1)
    logical :: found

    call open_data_file(path, unit, error)
    if (allocated(error)) return
    ! The tutorial's files open with a comment naming the case: that is the scene's title.
    call read_line(unit, line, ios)
    line = adjustl(line)
    if (ios == 0 .and. len(line) > 0) then
      if (line(1:1) == '#') call set_text(input, i_title, trim(adjustl(line(2:))))
    end if
    rewind(unit)
    n_read = 0
    line_number = 0
    do
      call next_data_line(unit, line, line_number, found)
      if (.not. found) exit
      n_read = n_read + 1
      if (n_read <= size(dat_order)) then
        ! A null (',', '1*') would leave value as the line before set it, or the first line
        ! uninitialised.
        call read_numbers(line, value, status)
        if (status /= number_ok) then
          close(unit)
          call raise(error, status_input, path // ':' // trim(fmt(line_number)) // ': ''' // trim(adjustl(line)) // &
            trim(merge(''' holds no number  ', ''' is not one number', status == number_null)) // ' (expected ' // &
            trim(real_names(dat_order(n_read))) // ')')
          return
        end if
        input%value(dat_order(n_read)) = value(1)
        input%given(dat_order(n_read)) = .true.
      else if (n_read == size(dat_order) + 1) then
        call set_text(input, i_f1_table, trim(beside(path, trim(adjustl(line)))))
      else
        close(unit)
        call raise(error, status_input, path // ':' // trim(fmt(line_number)) // &
          ': more entries than the 17 numbers and an f1 table file')
        return
      end if
    end do
    close(unit)
    if (n_read < size(dat_order)) then
      if (n_read == 0) then
        call raise(error, status_input, path // ': the file is empty')
      else
        call raise(error, status_input, path // ': ' // trim(fmt(n_read)) // ' numbers, 17 expected; ' // &
          trim(real_names(dat_order(n_read + 1))) // ' and after are missing')
      end if
      return
    end if
    ! One friction coefficient for both bodies, and the tutorial's gravity.
    input%value(i_mu2) = input%value(i_mu1)
    input%given(i_mu2) = .true.
    input%value(i_g) = dat_gravity
    input%given(i_g) = .true.
  end subroutine read_dat

  !> A two-column table 't f': '#' comments, times strictly increasing, at least one row.
  subroutine read_table(path, table, error)
    character(len=*), intent(in) :: path
    type(table_type), intent(out) :: table
    type(error_type), allocatable, intent(out) :: error
    integer :: unit, line_number, n, status
    character(len=:), allocatable :: line
    real(wp) :: row(2)
    real(wp), allocatable :: t(:), f(:)
    logical :: found

    call open_data_file(path, unit, error)
    if (allocated(error)) return
    allocate(t(16), f(16))
    n = 0
    line_number = 0
    do
      call next_data_line(unit, line, line_number, found)
      if (.not. found) exit
      ! A null (', 5') would leave the row's earlier values.
      call read_numbers(line, row, status)
      if (status /= number_ok) then
        call fail(': malformed row ''' // trim(adjustl(line)) // ''': expected two numbers "t f"')
        return
      end if
      if (.not. all(ieee_is_finite(row))) then
        call fail(': ' // trim(adjustl(line)) // ' is not finite')
        return
      end if
      if (n > 0) then
        if (row(1) <= t(n)) then
          call fail(': time ' // trim(fmt(row(1))) // ' does not increase (after ' // trim(fmt(t(n))) // ')')
          return
        end if
      end if
      if (n == size(t)) then
        t = [t, t]
        f = [f, f]
      end if
      n = n + 1
      t(n) = row(1)
      f(n) = row(2)
    end do
    close(unit)
    if (n == 0) then
      call raise(error, status_input, path // ': the table has no rows')
      return
    end if
    table%t = t(:n)
    table%f = f(:n)
  contains
    subroutine fail(what)
      character(len=*), intent(in) :: what
      close(unit)
      call raise(error, status_input, path // ':' // trim(fmt(line_number)) // what)
    end subroutine fail
  end subroutine read_table

  !> Open a file for reading; a missing or unreadable one, or anything but a regular file
  !> (check_input_file: a folder, FIFO, device), is an input error naming it.
  subroutine open_data_file(path, unit, error)
    character(len=*), intent(in) :: path
    integer, intent(out) :: unit
    type(error_type), allocatable, intent(out) :: error
    integer :: ios
    character(len=512) :: message
    call check_input_file(path, error)
    if (allocated(error)) return
    open(newunit=unit, file=path, status='old', action='read', iostat=ios, iomsg=message)
    if (ios /= 0) call raise(error, status_input, path // ': ' // trim(message))
  end subroutine open_data_file

  !> One whole line, whatever its length (a fixed buffer would cut long lines, and a long
  !> buffer makes every list-directed read of a short line scan its blanks). ios is 0, or
  !> negative at the end of the file; a last line without its newline still counts.
  subroutine read_line(unit, line, ios)
    integer, intent(in) :: unit
    character(len=:), allocatable, intent(out) :: line
    integer, intent(out) :: ios
    character(len=256) :: chunk
    integer :: n
    line = ''
    do
      read(unit, '(a)', advance='no', iostat=ios, size=n) chunk
      line = line // chunk(:n)
      if (ios /= 0) exit
    end do
    if (is_iostat_eor(ios) .or. (is_iostat_end(ios) .and. len(line) > 0)) ios = 0
  end subroutine read_line

  !> The next line that holds data: '#' starts a comment, blank lines are skipped.
  !> line_number counts every line read; found is false at the end of the file.
  subroutine next_data_line(unit, line, line_number, found)
    integer, intent(in) :: unit
    character(len=:), allocatable, intent(out) :: line
    integer, intent(inout) :: line_number
    logical, intent(out) :: found
    integer :: ios, hash
    found = .false.
    do
      call read_line(unit, line, ios)
      if (ios /= 0) return
      line_number = line_number + 1
      hash = index(line, '#')
      if (hash > 0) line = line(:hash - 1)
      if (len_trim(line) > 0) exit
    end do
    found = .true.
  end subroutine next_data_line

  !> A path written in a scene file is relative to that file's folder.
  pure function beside(scene_path, path) result(resolved)
    character(len=*), intent(in) :: scene_path, path
    character(len=len(scene_path) + len(path)) :: resolved    ! blank padded
    integer :: slash
    resolved = path
    if (len_trim(path) == 0 .or. path(1:1) == '/') return
    slash = index(scene_path, '/', back=.true.)
    if (slash > 0) resolved = scene_path(:slash) // path
  end function beside

  !> text in lower case (ASCII letters only): group and method names are case-insensitive.
  pure function lower(text) result(low)
    character(len=*), intent(in) :: text
    character(len=len(text)) :: low
    integer :: j
    low = text
    do j = 1, len(text)
      if (text(j:j) >= 'A' .and. text(j:j) <= 'Z') low(j:j) = achar(iachar(text(j:j)) + 32)
    end do
  end function lower
end module impact1d_io
