!> Reading scenes: the namelist format, the tutorial's VisSim-style parameter files and
!> force tables. Every problem comes back as an input error naming the file, line or variable.
module impact1d_io
  use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, raise, status_input, fmt
  use impact1d_scene, only: scene_input, scene_type, build_scene, validate, n_real, real_names, &
    i_m1, i_m2, i_mu1, i_mu2, i_g, i_r_left, i_r_right, i_r_min, i_r_max, i_x_left, i_x_right, &
    i_d_min, i_d_max, i_x1, i_x2, i_v1, i_v2, i_f1, i_f2, i_title, i_f1_table, i_f2_table, i_method
  use impact1d_forcing, only: table_type
  implicit none
  private
  public :: read_scene_file, prepare_scene, read_table, lower

  !> Fills for the namelist variables before reading; a variable is given when it is not
  !> its fill after either of two reads over different fills (see read_namelist).
  real(wp), parameter :: absent = huge(1.0_wp)
  character(len=*), parameter :: absent_text = achar(1), absent_text_other = achar(2)
  character(len=*), parameter :: known_groups(8) = [character(len=7) :: &
    'scene', 'bodies', 'walls', 'link', 'initial', 'forces', 'springs', 'run']
  !> Each group's variables, for the message about a misspelt one (as the namelists below).
  character(len=*), parameter :: group_variables(size(known_groups)) = [character(len=96) :: &
    'title', 'm1, m2, mu1, mu2, mus1, mus2, g', 'x_left, r_left, x_right, r_right', 'd_min, r_min, d_max, r_max', &
    'x1, v1, x2, v2', 'f1, f2, f1_table, f2_table, f1_amp, f1_period, f1_phase, f2_amp, f2_period, f2_phase', &
    'k1, x1_rest, c1, k2, x2_rest, c2, k12, d_rest, c12', &
    't_end, dt, dt_out, method, zero_vel, max_rows, max_impulses, max_step_events']
  !> The tutorial's parameter files list these, in its Table 1 order; g is 10 there.
  integer, parameter :: dat_order(17) = [i_m1, i_m2, i_mu1, i_r_left, i_r_right, i_r_min, &
    i_r_max, i_x_left, i_x_right, i_d_min, i_d_max, i_x1, i_x2, i_v1, i_v2, i_f1, i_f2]
  real(wp), parameter :: dat_gravity = 10.0_wp
  !> What read_numbers found: every number, text that is not numbers, or a value missing.
  integer, parameter :: number_ok = 0, number_malformed = 1, number_null = 2

contains

  !> Read a scene file: '.dat' is a VisSim-style parameter file, anything else a namelist.
  !> Checks what can be checked before the &run values are final.
  subroutine read_scene_file(path, input, error)
    character(len=*), intent(in) :: path
    type(scene_input), intent(out) :: input
    type(error_type), allocatable, intent(out) :: error
    integer :: n
    n = len_trim(path)
    if (n == 0) then
      call raise(error, status_input, 'no scene file given')
      return
    end if
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
    call validate(input, .false., error)
    if (allocated(error)) error%message = trim(path) // ': ' // error%message
  end subroutine read_scene_file

  !> Read the force tables a checked input names, then build the model.
  subroutine prepare_scene(input, scene, error)
    type(scene_input), intent(in) :: input
    type(scene_type), intent(out) :: scene
    type(error_type), allocatable, intent(out) :: error
    type(table_type) :: tables(2)
    integer :: i
    do i = 1, 2
      if (len_trim(input%text(i_f1_table + i - 1)) == 0) cycle
      call read_table(trim(input%text(i_f1_table + i - 1)), tables(i), error)
      if (allocated(error)) then
        error%message = 'f' // trim(fmt(i)) // '_table: ' // error%message
        return
      end if
    end do
    call build_scene(input, tables, scene, error)
  end subroutine prepare_scene

  subroutine read_namelist(path, input, error)
    character(len=*), intent(in) :: path
    type(scene_input), intent(inout) :: input
    type(error_type), allocatable, intent(out) :: error
    real(wp) :: m1, m2, mu1, mu2, g, x_left, r_left, x_right, r_right, d_min, r_min, d_max, r_max
    real(wp) :: x1, v1, x2, v2, f1, f2, f1_amp, f1_period, f1_phase, f2_amp, f2_period, f2_phase
    real(wp) :: t_end, dt, dt_out, zero_vel, max_rows, max_impulses, max_step_events
    real(wp) :: mus1, mus2, k1, x1_rest, c1, k2, x2_rest, c2, k12, d_rest, c12
    character(len=1024) :: title, f1_table, f2_table, method
    namelist /scene/ title
    namelist /bodies/ m1, m2, mu1, mu2, mus1, mus2, g
    namelist /walls/ x_left, r_left, x_right, r_right
    namelist /link/ d_min, r_min, d_max, r_max
    namelist /initial/ x1, v1, x2, v2
    namelist /forces/ f1, f2, f1_table, f2_table, f1_amp, f1_period, f1_phase, f2_amp, f2_period, f2_phase
    namelist /springs/ k1, x1_rest, c1, k2, x2_rest, c2, k12, d_rest, c12
    namelist /run/ t_end, dt, dt_out, method, zero_vel, max_rows, max_impulses, max_step_events
    logical :: present(size(known_groups))
    integer :: ios, j
    character(len=512) :: message
    real(wp) :: values(n_real), values_other(n_real)
    character(len=1024) :: texts(4), texts_other(4)
    character(len=:), allocatable :: lines(:), reason

    call scan_groups(path, present, error)
    if (allocated(error)) return
    ! The namelist reader reads the file's lines as an internal file: reading the file itself
    ! it hit its end on a last line without a newline ("in &run: End of file").
    call read_all_lines(path, lines, error)
    if (allocated(error)) return
    do j = 1, size(known_groups)
      if (any(trim(known_groups(j)) == ['bodies ', 'initial', 'run    ']) .and. .not. present(j)) then
        call raise(error, status_input, path // ': the required group &' // trim(known_groups(j)) // &
          ' is missing')
        return
      end if
    end do

    ! Whether a variable was given cannot depend on its value: the file is read twice, over
    ! two different fills; a variable the file sets reads the same both times.
    call read_groups(absent, absent_text, values, texts)
    if (allocated(error)) return
    call read_groups(-absent, absent_text_other, values_other, texts_other)
    if (allocated(error)) return
    input%given = .not. (values == absent .and. values_other == -absent)
    input%value = merge(values, 0.0_wp, input%given)
    title = texts(1)
    f1_table = texts(2)
    f2_table = texts(3)
    method = texts(4)
    do j = 1, size(texts)
      if (texts(j) /= absent_text .or. texts_other(j) /= absent_text_other) cycle
      if (j == 1) title = absent_text
      if (j == 2) f1_table = absent_text
      if (j == 3) f2_table = absent_text
      if (j == 4) method = absent_text
    end do
    input%text(i_title) = given_text(title)
    input%text(i_f1_table) = beside(path, given_text(f1_table))
    input%text(i_f2_table) = beside(path, given_text(f2_table))
    input%text(i_method) = lower(given_text(method))

  contains

    !> Every variable set to fill (texts to text_fill), then every group present read.
    subroutine read_groups(fill, text_fill, values, texts)
      real(wp), intent(in) :: fill
      character(len=*), intent(in) :: text_fill
      real(wp), intent(out) :: values(n_real)
      character(len=1024), intent(out) :: texts(4)
      m1 = fill; m2 = fill; mu1 = fill; mu2 = fill; g = fill
      x_left = fill; r_left = fill; x_right = fill; r_right = fill
      d_min = fill; r_min = fill; d_max = fill; r_max = fill
      x1 = fill; v1 = fill; x2 = fill; v2 = fill; f1 = fill; f2 = fill
      f1_amp = fill; f1_period = fill; f1_phase = fill
      f2_amp = fill; f2_period = fill; f2_phase = fill
      t_end = fill; dt = fill; dt_out = fill; zero_vel = fill
      max_rows = fill; max_impulses = fill; max_step_events = fill
      mus1 = fill; mus2 = fill; k1 = fill; x1_rest = fill; c1 = fill; k2 = fill; x2_rest = fill
      c2 = fill; k12 = fill; d_rest = fill; c12 = fill
      title = text_fill; f1_table = text_fill; f2_table = text_fill; method = text_fill
      do j = 1, size(known_groups)
        if (.not. present(j)) cycle
        select case (trim(known_groups(j)))
        case ('scene'); read(lines, nml=scene, iostat=ios, iomsg=message)
        case ('bodies'); read(lines, nml=bodies, iostat=ios, iomsg=message)
        case ('walls'); read(lines, nml=walls, iostat=ios, iomsg=message)
        case ('link'); read(lines, nml=link, iostat=ios, iomsg=message)
        case ('initial'); read(lines, nml=initial, iostat=ios, iomsg=message)
        case ('forces'); read(lines, nml=forces, iostat=ios, iomsg=message)
        case ('springs'); read(lines, nml=springs, iostat=ios, iomsg=message)
        case ('run'); read(lines, nml=run, iostat=ios, iomsg=message)
        end select
        if (ios /= 0) then
          call plain_reason(trim(message), j, reason)
          call raise(error, status_input, path // ': in &' // trim(known_groups(j)) // ': ' // reason)
          return
        end if
      end do
      values = [m1, m2, mu1, mu2, g, x_left, r_left, x_right, r_right, d_min, r_min, d_max, r_max, &
        x1, v1, x2, v2, f1, f2, f1_amp, f1_period, f1_phase, f2_amp, f2_period, f2_phase, t_end, dt, &
        dt_out, zero_vel, max_rows, max_impulses, max_step_events, mus1, mus2, k1, x1_rest, c1, k2, &
        x2_rest, c2, k12, d_rest, c12]
      texts = [title, f1_table, f2_table, method]
    end subroutine read_groups
  end subroutine read_namelist

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

  !> The namelist reader's message in plain words: a misspelt variable gets the group's names.
  subroutine plain_reason(message, group, text)
    character(len=*), intent(in) :: message
    integer, intent(in) :: group
    character(len=:), allocatable, intent(out) :: text
    character(len=*), parameter :: unmatched = 'Cannot match namelist object name '
    integer :: at
    text = message
    at = index(message, unmatched)
    if (at == 0) return
    text = 'unknown variable ''' // trim(message(at + len(unmatched):)) // ''' (&' // &
      trim(known_groups(group)) // ' has: ' // trim(group_variables(group)) // ')'
  end subroutine plain_reason

  !> Which groups the file has, and the syntax the namelist reader would pass over in silence:
  !> a misspelt group (&wall), a group given twice, text outside any group, a group without
  !> its closing '/', and an assignment with no number (v1 = +). Quotes and '!' comments are
  !> followed, so a '/' inside a title does not end its group.
  subroutine scan_groups(path, present, error)
    character(len=*), intent(in) :: path
    logical, intent(out) :: present(size(known_groups))
    type(error_type), allocatable, intent(out) :: error
    character(len=*), parameter :: blanks = ' ' // achar(9) // achar(13)
    character(len=*), parameter :: name_chars = 'abcdefghijklmnopqrstuvwxyz' // &
      'ABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_'
    integer :: unit, ios, line_number, j, k, finish, group, group_line(size(known_groups)), open_group
    character(len=:), allocatable :: line, name
    character :: quote
    logical :: any_content

    present = .false.
    any_content = .false.
    group_line = 0
    open_group = 0
    quote = ' '
    call open_data_file(path, unit, error)
    if (allocated(error)) return
    line_number = 0
    do
      call read_line(unit, line, ios)
      if (ios /= 0) exit
      line_number = line_number + 1
      j = 1
      do while (j <= len(line))
        if (quote /= ' ') then
          if (line(j:j) == quote) quote = ' '
          j = j + 1
          cycle
        end if
        if (scan(line(j:j), blanks) > 0) then
          j = j + 1
          cycle
        end if
        if (line(j:j) == '!') exit
        any_content = .true.
        if (line(j:j) == '&' .or. line(j:j) == '$') then
          finish = verify(line(j + 1:) // ' ', name_chars) + j - 1
          name = lower(line(j + 1:finish))
          if (name == 'end' .and. open_group > 0) then
            open_group = 0
          else if (open_group > 0) then
            call fail('the group &' // trim(known_groups(open_group)) // ' (line ' // &
              trim(fmt(group_line(open_group))) // ') has no closing ''/'' before &' // name)
            return
          else
            group = 0
            do k = 1, size(known_groups)
              if (trim(known_groups(k)) == name) group = k
            end do
            if (group == 0) then
              call fail('unknown group &' // name // ' (groups: &scene &bodies &walls &link &initial &forces &springs &run)')
              return
            end if
            if (present(group)) then
              call fail('the group &' // name // ' is given twice (lines ' // trim(fmt(group_line(group))) // &
                ' and ' // trim(fmt(line_number)) // ')')
              return
            end if
            present(group) = .true.
            group_line(group) = line_number
            open_group = group
          end if
          j = finish + 1
          cycle
        end if
        if (open_group == 0) then
          call fail('text outside any group: ''' // trim(line(j:)) // '''')
          return
        end if
        select case (line(j:j))
        case ('/')
          open_group = 0
        case ('''', '"')
          quote = line(j:j)
        case ('=')
          ! A lone sign after '=' is no value to the namelist reader: the variable would
          ! silently stay absent.
          k = verify(line(j + 1:) // '!', blanks) + j
          if (k <= len(line)) then
            finish = scan(line(k:) // ',', ' ,/!' // achar(9)) + k - 2
            if (line(k:finish) == '+' .or. line(k:finish) == '-') then
              call fail('''' // trim(line(:j)) // ' ' // line(k:finish) // ''' has no number after its sign')
              return
            end if
          end if
        end select
        j = j + 1
      end do
    end do
    close(unit)
    if (open_group > 0) then
      call raise(error, status_input, path // ':' // trim(fmt(group_line(open_group))) // ': the group &' // &
        trim(known_groups(open_group)) // ' has no closing ''/'' (every group ends with /)')
    else if (.not. any_content) then
      call raise(error, status_input, path // ': the file is empty')
    end if

  contains

    subroutine fail(what)
      character(len=*), intent(in) :: what
      close(unit)
      call raise(error, status_input, path // ':' // trim(fmt(line_number)) // ': ' // what)
    end subroutine fail
  end subroutine scan_groups

  !> The numbers of one line (a table row, a .dat entry) as list-directed
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
    if (ios /= 0 .or. extra == 0) return
    status = number_null
    if (any(values == huge(1.0_wp) .and. again == -huge(1.0_wp))) return
    status = number_ok
  end subroutine read_numbers

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
      if (line(1:1) == '#') input%text(i_title) = adjustl(line(2:))
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
        input%text(i_f1_table) = beside(path, trim(adjustl(line)))
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

  !> Open a file for reading; a missing or unreadable one, or a folder, is an input error
  !> naming it.
  subroutine open_data_file(path, unit, error)
    character(len=*), intent(in) :: path
    integer, intent(out) :: unit
    type(error_type), allocatable, intent(out) :: error
    integer :: ios
    character(len=512) :: message
    logical :: folder
    inquire(file=path // '/.', exist=folder)
    if (folder) then
      call raise(error, status_input, path // ': is a folder, not a file')
      return
    end if
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

  pure function given_text(text) result(given)
    character(len=*), intent(in) :: text
    character(len=len(text)) :: given    ! blank padded
    given = ''
    if (text /= absent_text) given = text
  end function given_text

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
